// Lawson and Hanson's non-negative least squares (nnls.hpp).
#include "nnls.hpp"

#include <algorithm>
#include <cmath>

namespace physval::core_detail {

bool nnls(std::size_t R, std::size_t C, const std::vector<double>& B, const std::vector<double>& y,
          std::vector<double>& x) {
  std::vector<double> z(C), wv(C), res(R);
  const auto at = [&](std::size_t row, std::size_t k) -> double { return B[k * R + row]; };
  double ynorm = 0.0;
  for (double v : y) ynorm = std::max(ynorm, std::fabs(v));
  x.assign(C, 0.0);
  std::vector<char> active(C, 0);
  std::vector<std::size_t> P;
  std::vector<double> Q, rhs;
  // z = the least-squares solution on the active columns (0 elsewhere); false if singular.
  const auto solve = [&]() {
    const std::size_t n = P.size();
    Q.assign(R * n, 0.0);
    for (std::size_t j = 0; j < n; ++j) {
      for (std::size_t i = 0; i < R; ++i) Q[j * R + i] = at(i, P[j]);
    }
    rhs = y;
    double scale = 0.0;
    for (double v : Q) scale = std::max(scale, std::fabs(v));
    for (std::size_t j = 0; j < n; ++j) {   // Householder on column j, rows j..R-1
      if (j >= R) return false;
      double norm = 0.0;
      for (std::size_t i = j; i < R; ++i) norm += Q[j * R + i] * Q[j * R + i];
      norm = std::sqrt(norm);
      if (!(norm > 1e-13 * scale)) return false;
      const double alpha = Q[j * R + j] > 0.0 ? -norm : norm;
      std::vector<double> v(R - j);
      for (std::size_t i = j; i < R; ++i) v[i - j] = Q[j * R + i];
      v[0] -= alpha;
      double vv = 0.0;
      for (double e : v) vv += e * e;
      if (!(vv > 0.0)) continue;
      for (std::size_t jj = j; jj < n; ++jj) {
        double s = 0.0;
        for (std::size_t i = j; i < R; ++i) s += v[i - j] * Q[jj * R + i];
        s *= 2.0 / vv;
        for (std::size_t i = j; i < R; ++i) Q[jj * R + i] -= s * v[i - j];
      }
      double s = 0.0;
      for (std::size_t i = j; i < R; ++i) s += v[i - j] * rhs[i];
      s *= 2.0 / vv;
      for (std::size_t i = j; i < R; ++i) rhs[i] -= s * v[i - j];
    }
    std::fill(z.begin(), z.end(), 0.0);
    for (std::size_t j = n; j-- > 0;) {
      double s = rhs[j];
      for (std::size_t jj = j + 1; jj < n; ++jj) s -= Q[jj * R + j] * z[P[jj]];
      z[P[j]] = s / Q[j * R + j];
    }
    return true;
  };
  const auto gradient = [&]() {   // wv = B^T (y - B x)
    res = y;
    for (std::size_t k = 0; k < C; ++k) {
      if (x[k] == 0.0) continue;
      for (std::size_t i = 0; i < R; ++i) res[i] -= at(i, k) * x[k];
    }
    for (std::size_t k = 0; k < C; ++k) {
      double s = 0.0;
      for (std::size_t i = 0; i < R; ++i) s += at(i, k) * res[i];
      wv[k] = s;
    }
  };
  // A column that would make the active set singular is passed over until the next one
  // enters (Lawson and Hanson's test of the new column's pivot): its gradient is round-off
  // of a residual its set cannot lower. Before, the whole solve failed: a 1 kg ball resting
  // on two 1 g balls between touching walls, all with friction, has more cone edges than
  // its 6 rows, a seventh entered on a gradient of 1e-13 of the weights, and core reported a
  // hold it "could not show" (nineteenth hunt, finding 8).
  std::vector<char> passed(C, 0);
  gradient();
  for (std::size_t outer = 0; outer < 3 * C + 30; ++outer) {
    std::size_t t = C;
    double best = 1e-13 * ynorm;
    for (std::size_t k = 0; k < C; ++k) {
      if (!active[k] && !passed[k] && wv[k] > best) {
        best = wv[k];
        t = k;
      }
    }
    if (t == C) return true;   // no column would lower the residual: optimal
    active[t] = 1;
    P.push_back(t);
    bool dependent = false;
    for (int inner = 0;; ++inner) {
      if (inner > static_cast<int>(C) + 10) return false;
      if (!solve()) {
        if (inner > 0) return false;
        P.pop_back();   // x is as it was: the new column alone made the set singular
        active[t] = 0;
        passed[t] = 1;
        dependent = true;
        break;
      }
      bool positive = true;
      for (std::size_t k : P) positive = positive && z[k] > 0.0;
      if (positive) {
        for (std::size_t k : P) x[k] = z[k];
        break;
      }
      double alpha = 1.0;
      for (std::size_t k : P) {
        if (z[k] <= 0.0) alpha = std::min(alpha, x[k] / (x[k] - z[k]));
      }
      for (std::size_t k : P) x[k] += alpha * (z[k] - x[k]);
      std::vector<std::size_t> keep;
      for (std::size_t k : P) {
        if (x[k] > 0.0) {
          keep.push_back(k);
        } else {
          x[k] = 0.0;
          active[k] = 0;
        }
      }
      P = keep;
      if (P.empty()) break;
    }
    if (dependent) continue;
    std::fill(passed.begin(), passed.end(), 0);
    gradient();
  }
  return false;
}

}  // namespace physval::core_detail
