// Non-negative least squares: min |B x - y| over x >= 0, by Lawson and Hanson's active-set
// method, each unconstrained solve on the active columns by Householder QR (backward
// stable). Shared by the resting-contact judgement (exact least-squares contact forces,
// resting_contact.cpp) and the simultaneous-impact solve (the frictionless impact as a
// least-distance problem, simultaneous_impacts.cpp).
#pragma once

#include <cstddef>
#include <vector>

namespace physval::core_detail {

// B: R rows by C columns, column-major (B[k * R + i] is row i of column k); y: R values.
// x: the solution (C values). A column enters while its gradient B^T (y - B x) exceeds
// 1e-13 max|y|; a column that would make the active set singular (a column's remaining norm
// <= 1e-13 of B's largest entry, or more columns than rows) is passed over until another
// enters. False if it does not finish (3 C + 30 additions, C + 10 inner steps each) or a set
// turns singular within an addition's inner steps.
bool nnls(std::size_t R, std::size_t C, const std::vector<double>& B, const std::vector<double>& y,
          std::vector<double>& x);

}  // namespace physval::core_detail
