#pragma once
// Internal to pipelines/geometry: runs Eigen's Levenberg-Marquardt (MINPACK lmder)
// for at most `max_iterations` outer iterations on a functor deriving from
// Eigen::DenseFunctor<double> with operator() and df().
#include <unsupported/Eigen/LevenbergMarquardt>

namespace procam::geom::detail {

struct LmOutcome {
  int iterations = 0;
  bool converged = false;  // stopped on a tolerance, not on the iteration limit
};

template <class Functor>
LmOutcome runLevenbergMarquardt(Functor& functor, Eigen::VectorXd& x, int max_iterations) {
  Eigen::LevenbergMarquardt<Functor> lm(functor);
  lm.setXtol(1e-12);
  lm.setFtol(1e-12);
  lm.setMaxfev(10 * max_iterations + 10);
  LmOutcome out;
  auto status = lm.minimizeInit(x);
  if (status == Eigen::LevenbergMarquardtSpace::ImproperInputParameters) return out;
  do {
    status = lm.minimizeOneStep(x);
    ++out.iterations;
  } while (status == Eigen::LevenbergMarquardtSpace::Running && out.iterations < max_iterations);
  out.converged = status != Eigen::LevenbergMarquardtSpace::Running &&
                  status != Eigen::LevenbergMarquardtSpace::TooManyFunctionEvaluation &&
                  status != Eigen::LevenbergMarquardtSpace::UserAsked;
  return out;
}

}  // namespace procam::geom::detail
