// source.table: a column of a CSV file against its time column, linearly interpolated and held
// constant outside the table. Its values are data, not parameters: its tangent is zero.
#include "blocks/time_series.hpp"
#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::Seeds;

class Table : public Block {
 public:
  explicit Table(const engine::BlockSettings& s)
      : series_(read_time_series(s, "file", s.text("time_column"), {s.text("column")}, "column").front()) {
    declare_output("y", 1);
  }
  const TimeSeries& series() const { return series_; }
  void outputs(const Eval& e, double* const* y) const override { y[0][0] = series_.linear(e.t); }
  void outputs_tangent(const Eval&, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d) dy[0](0, d) = 0.0;
  }

 private:
  TimeSeries series_;
};

const engine::BlockRegistration table({
    "source.table", "sources", "A CSV column against time, linearly interpolated.",
    {},
    {{"file", "CSV file, relative to the scene", "", true},
     {"column", "column to output", "", true},
     {"time_column", "column holding time [s]", "t", false}},
    [](const engine::BlockSettings& s) -> std::unique_ptr<Block> { return std::make_unique<Table>(s); },
    {{"file covers [time.start, time.stop]", "file", engine::BlockCheck::Severity::warning,
      [](const engine::CheckInput& in) -> std::optional<std::string> {
        const auto* table = dynamic_cast<const Table*>(in.block);
        return table ? uncovered_span(table->series(), in.t_start, in.t_stop) : std::nullopt;
      }}}});

}  // namespace
}  // namespace dydp::blocks
