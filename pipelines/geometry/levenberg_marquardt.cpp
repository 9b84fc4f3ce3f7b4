#include "geometry/levenberg_marquardt.hpp"

#include <unsupported/Eigen/LevenbergMarquardt>

namespace procam::geom::detail {
namespace {

struct CallbackFunctor : Eigen::DenseFunctor<double> {
  const LeastSquaresProblem& problem;
  explicit CallbackFunctor(const LeastSquaresProblem& p)
      : DenseFunctor<double>(p.parameters, p.residuals), problem(p) {}
  int operator()(const InputType& x, ValueType& f) const {
    problem.residual(x, f);
    return 0;
  }
  int df(const InputType& x, JacobianType& J) const {
    problem.jacobian(x, J);
    return 0;
  }
};

}  // namespace

LmOutcome runLevenbergMarquardt(const LeastSquaresProblem& problem, Eigen::VectorXd& x,
                                int max_iterations) {
  CallbackFunctor functor(problem);
  Eigen::LevenbergMarquardt<CallbackFunctor> lm(functor);
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
