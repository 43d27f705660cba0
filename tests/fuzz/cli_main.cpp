// The dydp program's main (apps/dydp/main.cpp: the CLI11 parsing and the dispatch to the
// commands) compiled as a function, dydp_cli_main, that cli_fuzz calls in-process. main() neither
// calls exit() nor keeps state between calls (RankSession does nothing outside mpirun), so it is
// used as it stands.
#define main dydp_cli_main
#include "apps/dydp/main.cpp"
