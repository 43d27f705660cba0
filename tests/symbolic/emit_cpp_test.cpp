// Emitted C++ is compiled by the project's compiler into a shared object, loaded, and run
// against the interpreter on the same lists: plain functions, parameter derivatives, tangents;
// and built with and without its vector clones, which must agree to the bit.
#include "symbolic/emit_cpp.hpp"

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "eval_helpers.hpp"
#include "random_list.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"

namespace dydp::symbolic {
namespace {

namespace fs = std::filesystem;

using Plain = void (*)(const double*, const double*, const double*, double*);
using TangentFn = void (*)(const double*, const double*, const double*, int, const double*,
                           const double*, double*, double*);

class SharedObject {
 public:
  // Compiles `source` into a shared object in a fresh directory and loads it.
  explicit SharedObject(const std::string& source, const std::string& tag, const std::string& flags = "") {
    dir_ = fs::path(DYDP_TEST_WORK_DIR) / ("emit_" + tag + "_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "model.cpp") << source;
    const std::string command = std::string("\"") + DYDP_TEST_CXX_COMPILER +
                                "\" -std=c++20 -O2 -Wall -Wextra -Werror -shared -fPIC " + flags + " -o \"" +
                                (dir_ / "model.so").string() + "\" \"" +
                                (dir_ / "model.cpp").string() + "\" 2> \"" +
                                (dir_ / "compile.log").string() + "\"";
    status_ = std::system(command.c_str());
    if (status_ == 0) handle_ = dlopen((dir_ / "model.so").c_str(), RTLD_NOW | RTLD_LOCAL);
  }
  ~SharedObject() {
    if (handle_) dlclose(handle_);
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  bool ok() const { return handle_ != nullptr; }
  std::string log() const {
    std::ifstream in(dir_ / "compile.log");
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  template <class F>
  F get(const char* name) const { return reinterpret_cast<F>(dlsym(handle_, name)); }

 private:
  fs::path dir_;
  int status_ = -1;
  void* handle_ = nullptr;
};

// A random list of 300 assignments emitted as one source: f, f_sens (along p[0] and p[2]) and
// f_tangent (seeded on q and qd), with C linkage.
struct RandomSource {
  Context ctx;
  testing::RandomModel model;
  EquationList list{ctx}, sens{ctx}, tangent{ctx};
  ArrayId seeded_arrays[2] = {0, 0};
  std::string source;

  explicit RandomSource(unsigned seed) {
    EquationList raw(ctx);
    model = testing::make_random_list(raw, 300, 6, seed);
    list = eliminate(raw);
    const Direction dirs[2] = {along(ctx.element(model.p, 0)), along(ctx.element(model.p, 2))};
    sens = eliminate(differentiate(list, dirs));
    seeded_arrays[0] = model.q;
    seeded_arrays[1] = model.qd;
    tangent = tangent_list(list, seeded_arrays);
    EmitOptions options;
    options.origin = "random list, seed " + std::to_string(seed);
    options.extern_c = true;
    options.function_name = "f";
    std::vector<EmittedFunction> functions{emit_function(list, options)};
    options.function_name = "f_sens";
    functions.push_back(emit_function(sens, options));
    options.function_name = "f_tangent";
    functions.push_back(emit_tangent(tangent, seeded_arrays, options));
    source = emit_source_file(functions, "", options);
  }
};

TEST(EmitCpp, CompiledFunctionsAgreeWithTheInterpreter) {
  RandomSource r(7);
  Context& ctx = r.ctx;
  const testing::RandomModel& model = r.model;
  const EquationList &list = r.list, &sens = r.sens, &tangent = r.tangent;
  const std::string& source = r.source;
  EXPECT_NE(source.find("noexcept"), std::string::npos);
  EXPECT_EQ(source.find("new "), std::string::npos);

  const SharedObject so(source, "random");
  ASSERT_TRUE(so.ok()) << "emitted code did not compile:\n" << so.log() << "\n" << source.substr(0, 4000);
  const auto f = so.get<Plain>("f");
  const auto f_sens = so.get<Plain>("f_sens");
  const auto f_tangent = so.get<TangentFn>("f_tangent");
  ASSERT_TRUE(f && f_sens && f_tangent);

  for (unsigned point = 0; point < 5; ++point) {
    testing::ArrayValues<double> x(ctx);
    for (std::size_t a = 0; a < x.values.size(); ++a) {
      x.values[a] = testing::random_values(x.values[a].size(), 1000 * point + static_cast<unsigned>(a), 1.3);
    }
    const double* q = x.values[model.q].data();
    const double* qd = x.values[model.qd].data();
    const double* p = x.values[model.p].data();
    for (const auto* l : {&list, &sens}) {
      const auto expected = testing::run(Tape(*l), x);
      std::vector<double> got(expected.size(), -1.0);
      (l == &list ? f : f_sens)(q, qd, p, got.data());
      for (std::size_t j = 0; j < got.size(); ++j) {
        EXPECT_TRUE(testing::close(got[j], expected[j], 1e-11)) << "output " << j << ": " << got[j] << " vs " << expected[j];
      }
    }
    // Tangent: nd directions, seeds direction-major; directions run two at a time, so one, an
    // even count and an odd count past one (a pair, then a last direction paired with zero seeds).
    const std::size_t m = list.outputs().size();
    for (const int nd : {1, 2, 3, 6}) {
      std::vector<double> seed_q(4 * nd), seed_qd(4 * nd);
      seed_q = testing::random_values(4 * nd, point + 50);
      seed_qd = testing::random_values(4 * nd, point + 60);
      std::vector<double> out(m), dout(m * nd);
      f_tangent(q, qd, p, nd, seed_q.data(), seed_qd.data(), out.data(), dout.data());
      const Tape tape(tangent);
      const ArrayId dq = ctx.seed_array(model.q), dqd = ctx.seed_array(model.qd);
      for (int d = 0; d < nd; ++d) {
        x.values[dq].assign(seed_q.begin() + 4 * d, seed_q.begin() + 4 * d + 4);
        x.values[dqd].assign(seed_qd.begin() + 4 * d, seed_qd.begin() + 4 * d + 4);
        const auto expected = testing::run(tape, x);
        for (std::size_t j = 0; j < m; ++j) {
          EXPECT_TRUE(testing::close(out[j], expected[j], 1e-11));
          EXPECT_TRUE(testing::close(dout[d * m + j], expected[m + j], 1e-11))
              << nd << " directions, direction " << d << " output " << j << ": " << dout[d * m + j] << " vs "
              << expected[m + j];
        }
      }
    }
  }
}

TEST(EmitCpp, VectorClonesAgreeToTheBitWithABaselineBuild) {
  // The emitted functions carry GCC's target_clones (AVX2 and the baseline, bound at load time):
  // the same source built with the attribute off runs the baseline code only. Both must give
  // the same numbers to the bit (no fused multiply-add in either), for plain functions and for
  // tangents in passes of two and one.
  RandomSource r(11);
  Context& ctx = r.ctx;
  const testing::RandomModel& model = r.model;
  const EquationList& list = r.list;
  const std::string& source = r.source;
  EXPECT_NE(source.find("target_clones(\"avx2\", \"default\")"), std::string::npos);
  const SharedObject cloned(source, "clones"), baseline(source, "baseline", "-DDYDP_VECTOR_CLONES=");
  ASSERT_TRUE(cloned.ok()) << cloned.log();
  ASSERT_TRUE(baseline.ok()) << baseline.log();
  const std::size_t m = list.outputs().size();
  const int nd = 3;
  for (unsigned point = 0; point < 5; ++point) {
    testing::ArrayValues<double> x(ctx);
    for (std::size_t a = 0; a < x.values.size(); ++a)
      x.values[a] = testing::random_values(x.values[a].size(), 700 * point + static_cast<unsigned>(a), 1.3);
    const double* q = x.values[model.q].data();
    const double* qd = x.values[model.qd].data();
    const double* p = x.values[model.p].data();
    const std::vector<double> seed_q = testing::random_values(4 * nd, point + 80);
    const std::vector<double> seed_qd = testing::random_values(4 * nd, point + 90);
    std::vector<double> out[2], tangent_out[2], dout[2];
    for (int build = 0; build < 2; ++build) {
      const SharedObject& so = build == 0 ? cloned : baseline;
      out[build].assign(m, -1.0);
      tangent_out[build].assign(m, -1.0);
      dout[build].assign(m * nd, -1.0);
      so.get<Plain>("f")(q, qd, p, out[build].data());
      so.get<TangentFn>("f_tangent")(q, qd, p, nd, seed_q.data(), seed_qd.data(), tangent_out[build].data(),
                                     dout[build].data());
    }
    EXPECT_EQ(out[0], out[1]) << "point " << point;
    EXPECT_EQ(tangent_out[0], tangent_out[1]) << "point " << point;
    EXPECT_EQ(dout[0], dout[1]) << "point " << point;
  }
}

TEST(EmitCpp, ReadableNamesAndOutputComments) {
  Context ctx;
  const ArrayId q = ctx.add_array("q", 3, SymbolKind::Input);
  const ArrayId qd = ctx.add_array("qd", 3, SymbolKind::Input);
  EquationList list(ctx);
  const Expr om22 = list.assign("OM22", ctx.element(qd, 0) * sin(ctx.element(q, 1)));
  const Expr om32 = list.assign("OM32", ctx.element(qd, 0) * cos(ctx.element(q, 1)));
  const Expr om23 = list.assign("OM23", om22 * cos(ctx.element(q, 2)) + om32 * sin(ctx.element(q, 2)));
  list.add_output("omega_y", om23);
  EmitOptions options;
  options.function_name = "angular_velocity";
  options.namespace_name = "chain3";
  options.origin = "three-joint chain";
  const EmittedFunction fn = emit_function(list, options);
  EXPECT_NE(fn.definition.find("const double S3 = std::sin(q[2]);"), std::string::npos) << fn.definition;
  EXPECT_NE(fn.definition.find("const double OM23 = OM22*C3 + OM32*S3;"), std::string::npos) << fn.definition;
  EXPECT_NE(fn.definition.find("out[0] = OM23;  // omega_y"), std::string::npos) << fn.definition;
  const SharedObject so(emit_source_file(std::span<const EmittedFunction>(&fn, 1), "", options), "names");
  EXPECT_TRUE(so.ok()) << so.log();
}

}  // namespace
}  // namespace dydp::symbolic
