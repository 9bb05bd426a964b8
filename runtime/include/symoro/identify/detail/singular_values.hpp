// Singular values of a tall matrix through its QR factor (internal to identify).
#pragma once

#include <Eigen/Core>

namespace symoro::identify::detail {

// W = Q R has the singular values of R, and the SVD of the small p x p R is cheap where the SVD
// of a 10^5 x p W is not: Householder QR runs in blocks, where JacobiSVD's own column-pivoting QR
// preconditioner runs a rank-one update per column. Descending, as JacobiSVD gives them.
Eigen::VectorXd tall_singular_values(const Eigen::MatrixXd& W);

}  // namespace symoro::identify::detail
