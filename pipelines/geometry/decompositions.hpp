#pragma once
// Internal to pipelines/geometry: the dense decompositions the estimators share,
// compiled once (dynamic sizes) instead of per estimator and per fixed size.
#include "core/types.hpp"

namespace procam::geom::detail {

struct NullVector {
  Eigen::VectorXd v;         // unit right singular vector of the smallest singular value
  Eigen::VectorXd singular;  // all singular values, descending (cols() of them)
};

// Least-squares null vector of a (tall) DLT system. The m x k system is first reduced
// by a Householder QR (same singular values, no squaring of the condition number as
// with the normal equations AᵀA); the k x k triangle then goes through a Jacobi SVD.
// Rows are zero-padded when m < k.
NullVector smallestRightSingularVector(const Eigen::MatrixXd& A);

// Singular values of A (descending), same reduction as above.
Eigen::VectorXd singularValues(const Eigen::MatrixXd& A);

// Orthonormal basis (k x (k-1)) of the complement of the unit vector v: the tangent
// space of the sphere at v, used to parametrise a scale-free matrix for LM.
Eigen::MatrixXd orthogonalComplement(const Eigen::VectorXd& v);

// Householder QR of a square matrix: A = Q R, Q orthogonal, R upper triangular.
void householderQr(const Eigen::MatrixXd& A, Eigen::MatrixXd& Q, Eigen::MatrixXd& R);

}  // namespace procam::geom::detail
