// libFuzzer target: the command line. The input is split at newlines into arguments (after
// argv[0] = "dydp") and given to the program's own main (parsing and dispatch, in-process:
// tests/fuzz/cli_main.cpp), run in a private folder holding small files the arguments can name:
// s.yaml (a mass-spring-damper scene with parameters, ranges and directions, 0.05 s), r.yaml (a
// 4-poster pad into a mass, 0.05 s) and b.csv (a recording for r.yaml). main must return
// 0, 1 (solver failure) or 2 (bad input, parsing included); a crash, a leak, undefined behaviour,
// a hang, any other status or an exception that reaches main's last catch (`error: ...`: neither
// InputError nor a solver failure) is a finding. Outputs go to the folder, emptied of everything else
// after each input; what the program prints on std::cout and std::cerr is discarded.
//
// Inputs that would leave the folder or ask for unbounded work are skipped (not run): an argument
// with '/' (another file of the machine: /dev/zero, the shipped scenes), more than 24 arguments
// or one longer than 200 bytes, and the options that set how much work a command does beyond
// small values: --step < 1e-4, --rtol < 1e-10, --atol < 1e-12, --range or --frequencies with
// N > 8, --samples > 4, --threads > 2, --time or --at beyond 1 s, --fd with more than 4 steps.
// The program's own limits (a million sweep points, a million screening samples, any step)
// are what a user may ask for; a fuzzer would only find that they take long.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

int dydp_cli_main(int argc, char** argv);

namespace {

namespace fs = std::filesystem;

const char* const kScene = R"(scene: fuzz_msd
time: {start: 0.0, stop: 0.05, output_step: 0.01}
solver: {method: bdf, rtol: 1.0e-6, atol: 1.0e-8}
parameters:
  mass:      {value: 1.5, unit: kg, range: [0.5, 3.0]}
  stiffness: {value: 40.0, unit: N/m, range: [10.0, 100.0]}
  damping:   {value: 1.2, unit: N s/m, range: [0.0, 5.0]}
sensitivities: [mass, stiffness, damping]
blocks:
  force: {type: source.sine, amplitude: 2.0, frequency: 0.8}
  body:  {type: mass_spring_damper, m: $mass, k: $stiffness, c: $damping, x0: 0.05, v0: 0.0}
  x_rms: {type: objective.rms, window: [0.0, 0.05]}
connections:
  - force.y -> body.f
  - body.x -> x_rms.in
outputs: [body.x, body.v, x_rms]
)";

const char* const kRigScene = R"(scene: fuzz_rig
time: {start: 0.0, stop: 0.05, output_step: 0.01}
solver: {method: bdf, rtol: 1.0e-6, atol: 1.0e-8}
blocks:
  rig: {type: road.fourposter, amplitude_fl: 0.01, frequency_fl: 1.5}
  pad: {type: math.demux, width: 4, indices: [0]}
  spring: {type: math.gain, k: 40000.0}
  body: {type: mass_spring_damper, m: 100.0, k: 40000.0, c: 800.0}
connections:
  - rig.z -> pad.u
  - pad.y -> spring.u
  - spring.y -> body.f
outputs: [rig.z, body.x]
)";

const char* const kRecording =
    "t,fl,fr,rl,rr,body.x\n0,0,0,0,0,0\n0.01,0.001,0,0,0,0\n0.02,0.002,0,0,0,1e-5\n"
    "0.03,0.003,0,0,0,2e-5\n0.04,0.002,0,0,0,3e-5\n0.05,0.001,0,0,0,3e-5\n";

/// The private folder (the process's working directory while the target runs), removed at exit.
class Folder {
 public:
  Folder() : root_(fs::temp_directory_path() / ("dydp_fuzz_cli_" + std::to_string(::getpid()))) {
    fs::remove_all(root_);
    fs::create_directories(root_);
    std::ofstream(root_ / "s.yaml") << kScene;
    std::ofstream(root_ / "r.yaml") << kRigScene;
    std::ofstream(root_ / "b.csv") << kRecording;
    fs::current_path(root_);
  }
  ~Folder() {
    std::error_code ignored;
    fs::current_path(fs::temp_directory_path(), ignored);
    fs::remove_all(root_, ignored);
  }
  /// Removes what a command wrote; rewrites the fixtures (a command may have replaced one).
  void reset() const {
    static const std::set<std::string> keep = {"s.yaml", "r.yaml", "b.csv"};
    std::error_code ignored;
    for (const auto& e : fs::directory_iterator(root_, ignored))
      if (!keep.count(e.path().filename().string())) fs::remove_all(e.path(), ignored);
    std::ofstream(root_ / "s.yaml", std::ios::trunc) << kScene;
    std::ofstream(root_ / "r.yaml", std::ios::trunc) << kRigScene;
    std::ofstream(root_ / "b.csv", std::ios::trunc) << kRecording;
  }

 private:
  fs::path root_;
};

/// The value of option `name` in args (`--name V` or `--name=V`), each occurrence.
std::vector<std::string> values_of(const std::vector<std::string>& args, const std::string& name) {
  std::vector<std::string> v;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == name && i + 1 < args.size()) v.push_back(args[i + 1]);
    if (args[i].rfind(name + "=", 0) == 0) v.push_back(args[i].substr(name.size() + 1));
  }
  return v;
}

/// strtod of the whole text; NaN when it is not a number (the program refuses those itself).
double number(const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  return end != s.c_str() ? v : std::nan("");
}

/// N of LO:HI:N (the last field), NaN when absent.
double range_points(const std::string& s) {
  const size_t colon = s.rfind(':');
  return colon == std::string::npos ? std::nan("") : number(s.substr(colon + 1));
}

bool bounded(const std::vector<std::string>& args) {
  if (args.size() > 24) return false;
  for (const std::string& a : args)
    if (a.size() > 200 || a.find('/') != std::string::npos) return false;
  for (const std::string& v : values_of(args, "--step"))
    if (number(v) < 1e-4) return false;
  for (const std::string& v : values_of(args, "--rtol"))
    if (number(v) < 1e-10) return false;
  for (const std::string& v : values_of(args, "--atol"))
    if (number(v) < 1e-12) return false;
  for (const char* o : {"--range", "--frequencies"})
    for (const std::string& v : values_of(args, o))
      if (range_points(v) > 8) return false;
  for (const std::string& v : values_of(args, "--samples"))
    if (number(v) > 4) return false;
  for (const std::string& v : values_of(args, "--threads"))
    if (number(v) > 2) return false;
  for (const char* o : {"--time", "--at"})
    for (const std::string& v : values_of(args, o))
      if (std::fabs(number(v)) > 1) return false;
  for (const std::string& v : values_of(args, "--fd"))
    if (std::count(v.begin(), v.end(), ',') > 3) return false;
  size_t fd_options = values_of(args, "--fd").size();
  return fd_options <= 4;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const Folder folder;
  static std::ostringstream discarded, errors;
  std::vector<std::string> args{"dydp"};
  std::string current;
  for (size_t i = 0; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n') {
      args.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  if (!current.empty()) args.push_back(current);
  if (!bounded({args.begin() + 1, args.end()})) return 0;

  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::streambuf* out = std::cout.rdbuf(discarded.rdbuf());
  std::streambuf* err = std::cerr.rdbuf(errors.rdbuf());
  const int status = dydp_cli_main(static_cast<int>(args.size()), argv.data());
  std::cout.rdbuf(out);
  std::cerr.rdbuf(err);
  const std::string messages = "\n" + errors.str();
  discarded.str("");
  errors.str("");
  folder.reset();
  if (status != 0 && status != 1 && status != 2) __builtin_trap();
  // "error: ..." is main's last catch (a std::exception that is neither bad input nor a solver
  // failure): an exception the program did not mean to throw.
  if (messages.find("\nerror: ") != std::string::npos) __builtin_trap();
  return 0;
}
