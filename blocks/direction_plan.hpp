// Which directions of a tangent call need a pass of their own. A tangent is linear in its seeds:
// a direction whose seeds are all zero has a zero tangent, and directions whose one nonzero seed
// is the same entry of the same seed matrix are multiples of one unit direction. In a Jacobian
// pass the four states of a damper reach the car through its one force input: one pass on that
// input's unit seed serves all four, each scaled by its seed.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <initializer_list>
#include <vector>

namespace dydp::blocks {

class DirectionPlan {
 public:
  using Matrix = Eigen::MatrixXd;

  /// Plans the passes for nd directions seeded by `matrices` (column d: direction d). With
  /// shared >= 0, directions whose one nonzero seed is in matrices[shared] at a row below
  /// shared_rows share a pass with the others on the same row, when there are others.
  void build(std::initializer_list<const Matrix*> matrices, int nd, int shared = -1, int shared_rows = 0) {
    nd_ = nd;
    shared_ = shared >= 0 ? matrices.begin()[shared] : nullptr;
    passes_.clear();
    uses_.assign(nd, Use{});
    unit_row_.assign(nd, -1);
    unit_value_.assign(nd, 0.0);
    row_count_.assign(shared_rows > 0 ? shared_rows : 0, 0);
    row_pass_.assign(row_count_.size(), -1);
    std::vector<char>& live = live_;
    live.assign(nd, 0);
    for (int d = 0; d < nd; ++d) {
      // the first nonzero seed, then (only if it may be a shared one) whether there is another
      int count = 0, which = -1, row = -1, m = 0;
      double value = 0.0;
      for (const Matrix* a : matrices) {
        const double* col = a->data() + static_cast<Eigen::Index>(d) * a->rows();
        for (Eigen::Index i = 0; i < a->rows(); ++i)
          if (col[i] != 0.0) {
            if (++count == 2) break;
            which = m, row = static_cast<int>(i), value = col[i];
            if (m != shared || row >= shared_rows) break;
          }
        if (count >= 2 || (count == 1 && (which != shared || row >= shared_rows))) break;
        ++m;
      }
      live[d] = count > 0;
      if (count == 1 && which == shared && row < shared_rows) {
        unit_row_[d] = row, unit_value_[d] = value;
        ++row_count_[row];
      }
    }
    whole_ = true;
    for (int d = 0; d < nd; ++d) {
      if (!live[d]) {
        whole_ = false;
        continue;
      }
      const int row = unit_row_[d];
      if (row >= 0 && row_count_[row] >= 2) {
        whole_ = false;
        if (row_pass_[row] < 0) {
          row_pass_[row] = passes();
          passes_.push_back({d, row});
        }
        uses_[d] = {row_pass_[row], unit_value_[d], false};
      } else {
        uses_[d] = {passes(), 1.0, true};
        passes_.push_back({d, -1});
      }
    }
  }

  /// Number of passes (columns of the gathered seeds).
  int passes() const { return static_cast<int>(passes_.size()); }
  /// Every direction a pass of its own, in order: the seeds serve as they are.
  bool whole() const { return whole_; }

  /// The seeds of the passes from `a` (rows x nd): a shared pass has the unit seed in the
  /// shared matrix (the very object given to build()) and zero in any other. b is
  /// rows x max(1, passes).
  void gather(const Matrix& a, Matrix& b) const {
    b.resize(a.rows(), std::max(1, passes()));
    if (passes_.empty()) b.setZero();
    for (int c = 0; c < passes(); ++c) {
      const Pass& pass = passes_[c];
      if (pass.row < 0) {
        b.col(c) = a.col(pass.direction);
      } else {
        b.col(c).setZero();
        if (&a == shared_) b(pass.row, c) = 1.0;
      }
    }
  }

  /// The tangents of the nd directions, a[d * a_stride + i] for i < rows, from those of the
  /// passes, b[c * b_stride + i]: copied, scaled by the direction's seed, or zero.
  void scatter(const double* b, Eigen::Index b_stride, int rows, double* a, Eigen::Index a_stride) const {
    for (int d = 0; d < nd_; ++d) {
      double* to = a + d * a_stride;
      const Use& use = uses_[d];
      if (use.pass < 0) {
        std::fill(to, to + rows, 0.0);
      } else {
        const double* from = b + use.pass * b_stride;
        if (use.copy) std::copy(from, from + rows, to);
        else
          for (int i = 0; i < rows; ++i) to[i] = use.scale * from[i];
      }
    }
  }
  /// The same into a rows x max(1, nd) matrix.
  void scatter(const Matrix& b, int rows, Matrix& a) const {
    a.resize(rows, std::max(nd_, 1));
    if (nd_ == 0) a.setZero();
    scatter(b.data(), b.rows(), rows, a.data(), a.rows());
  }

 private:
  struct Pass {
    int direction;  ///< the direction whose seeds it takes (row < 0), or the first that shares it
    int row;        ///< >= 0: the unit seed of this row of the shared matrix
  };
  struct Use {
    int pass = -1;  ///< -1: a zero tangent
    double scale = 0.0;
    bool copy = false;
  };
  int nd_ = 0;
  const Matrix* shared_ = nullptr;
  bool whole_ = true;
  std::vector<Pass> passes_;
  std::vector<Use> uses_;
  // work space of build(), kept so that a plan allocates nothing once sized
  std::vector<int> unit_row_, row_count_, row_pass_;
  std::vector<double> unit_value_;
  std::vector<char> live_;
};

}  // namespace dydp::blocks
