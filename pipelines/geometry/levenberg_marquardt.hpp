#pragma once
// Internal to pipelines/geometry: one instantiation of Eigen's Levenberg-Marquardt
// (MINPACK lmder) shared by the estimators, driven through callbacks.
#include <functional>

#include "core/types.hpp"

namespace procam::geom::detail {

struct LeastSquaresProblem {
  int parameters = 0;
  int residuals = 0;
  // f(x) -> residual vector (size `residuals`), J(x) -> residuals x parameters.
  std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)> residual;
  std::function<void(const Eigen::VectorXd&, Eigen::MatrixXd&)> jacobian;
};

struct LmOutcome {
  int iterations = 0;
  bool converged = false;  // stopped on a tolerance, not on the iteration limit
};

// Minimises |f(x)|² from x for at most max_iterations outer iterations.
LmOutcome runLevenbergMarquardt(const LeastSquaresProblem& problem, Eigen::VectorXd& x,
                                int max_iterations);

}  // namespace procam::geom::detail
