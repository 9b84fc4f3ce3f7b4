#include "geometry/decompositions.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>

namespace procam::geom::detail {
namespace {

Eigen::MatrixXd reduceToSquare(const Eigen::MatrixXd& A) {
  const Eigen::Index k = A.cols();
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(k, k);
  if (A.rows() > k) {
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
    R = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  } else {
    R.topRows(A.rows()) = A;
  }
  return R;
}

}  // namespace

NullVector smallestRightSingularVector(const Eigen::MatrixXd& A) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(reduceToSquare(A), Eigen::ComputeFullV);
  return {svd.matrixV().col(A.cols() - 1), svd.singularValues()};
}

Eigen::VectorXd singularValues(const Eigen::MatrixXd& A) {
  return Eigen::JacobiSVD<Eigen::MatrixXd>(reduceToSquare(A)).singularValues();
}

Eigen::MatrixXd orthogonalComplement(const Eigen::VectorXd& v) {
  // The Householder reflection taking v to ±|v| e1 is symmetric and orthogonal; its
  // first column is ±v/|v|, the others span the complement.
  const Eigen::MatrixXd Q = Eigen::MatrixXd(v).householderQr().householderQ();
  return Q.rightCols(v.size() - 1);
}

void householderQr(const Eigen::MatrixXd& A, Eigen::MatrixXd& Q, Eigen::MatrixXd& R) {
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
  Q = qr.householderQ();
  R = qr.matrixQR().triangularView<Eigen::Upper>();
}

}  // namespace procam::geom::detail
