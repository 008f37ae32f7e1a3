// Python bindings of the double-precision inverse-velocity references (pinv.hpp): the seed's
// coordinate exclusion as an active set, and damped least squares.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "tensor_servo/pinv.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace {
py::dict result(const ts::PinvResult& r) {
  std::vector<int> active;
  for (auto a : r.active) active.push_back(static_cast<int>(a));
  const char* st = r.status == ts::PinvStatus::Converged ? "converged"
                   : r.status == ts::PinvStatus::IterationCap ? "iteration_cap" : "invalid_input";
  return py::dict("qd"_a = r.qd, "active"_a = active, "iterations"_a = r.iterations, "readmissions"_a = r.readmissions,
                  "status"_a = st, "objective"_a = r.objective, "residual"_a = r.residual, "lambda"_a = r.lambda,
                  "sigma_min"_a = r.sigma_min);
}
ts::Exclusion exclusion(const std::string& e) {
  if (e == "active_set") return ts::Exclusion::ActiveSet;
  if (e == "seed") return ts::Exclusion::Seed;
  throw std::invalid_argument("exclusion: 'active_set' or 'seed'");
}
}  // namespace

void bind_pinv(py::module_& m) {
  m.def("box_lsq", [](const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                      const std::string& excl) {
    ts::PinvOptions o; o.exclusion = exclusion(excl);
    return result(ts::box_lsq(A, b, lo, hi, o));
  }, py::arg("A"), py::arg("b"), py::arg("lower"), py::arg("upper"), py::arg("exclusion") = "active_set",
     "min 1/2 |b - A x|^2 on the box lower <= x <= upper (pinv.hpp box_lsq)");
  m.def("pinv_solve", [](const Eigen::MatrixXd& J, const Eigen::VectorXd& V, double L, const Eigen::VectorXd& lo,
                         const Eigen::VectorXd& hi, const std::string& excl) {
    ts::PinvOptions o; o.exclusion = exclusion(excl);
    return result(ts::pinv_solve(J, V, L, lo, hi, o));
  }, py::arg("J"), py::arg("V"), py::arg("L"), py::arg("lower"), py::arg("upper"), py::arg("exclusion") = "active_set");
  m.def("dls_solve", [](const Eigen::MatrixXd& J, const Eigen::VectorXd& V, double L, double lambda_max, double eps,
                        const Eigen::VectorXd& lo, const Eigen::VectorXd& hi) {
    ts::DlsOptions o;
    o.damping = ts::Damping::Adaptive;
    o.eps = eps;
    return result(ts::dls_solve(J, V, L, lambda_max, lo, hi, o));
  }, py::arg("J"), py::arg("V"), py::arg("L"), py::arg("lambda_max"), py::arg("eps"), py::arg("lower"), py::arg("upper"),
     "adaptive damped least squares on the box (pinv.hpp dls_solve)");
}
