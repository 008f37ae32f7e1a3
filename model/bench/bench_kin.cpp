// Benchmark: FK of every frame + the tool Jacobian (omega; v) in the root axes, per call, for the
// C++ model (double, default, compact) and Pinocchio (computeFrameJacobian, LOCAL_WORLD_ALIGNED),
// on the same chains and the same joint values, in one process.
//
// usage: bench_kin CHAIN.txt [seconds_per_case]
// CHAIN.txt (written by scripts/bench.py): n; base quat(4) xyz(3); tool quat(4) xyz(3); then per
// joint: prismatic quat(4) xyz(3) axis(3) scale limited lower upper.
// Output: one line per implementation: "<impl> <ns_per_call_min> <ns_per_call_median> <checksum>".
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/multibody.hpp>

#include "bench_common.hpp"

using namespace ts;
using namespace tsbench;
constexpr int NM = 32;

static pinocchio::SE3 se3(const double* q, const double* p) {
  const Eigen::Quaterniond qq(q[0], q[1], q[2], q[3]);
  return pinocchio::SE3(qq.toRotationMatrix(), Eigen::Vector3d(p[0], p[1], p[2]));
}

// Pinocchio's fastest joint type for each axis: RX/RY/RZ (PX/PY/PZ) when axis-aligned.
static pinocchio::JointModel joint_model(const JointSpec& j) {
  const Eigen::Vector3d a(j.axis[0], j.axis[1], j.axis[2]);
  for (int k = 0; k < 3; ++k)
    if (a[k] == 1.0) {
      if (!j.prismatic) {
        if (k == 0) return pinocchio::JointModelRX();
        if (k == 1) return pinocchio::JointModelRY();
        return pinocchio::JointModelRZ();
      }
      if (k == 0) return pinocchio::JointModelPX();
      if (k == 1) return pinocchio::JointModelPY();
      return pinocchio::JointModelPZ();
    }
  if (j.prismatic) return pinocchio::JointModelPrismaticUnaligned(a);
  return pinocchio::JointModelRevoluteUnaligned(a);
}

template <class Fmt>
static void bench_model(const char* name, const ChainSpec& c, const std::vector<std::vector<double>>& qs, double sec) {
  static ChainQ<Fmt, NM> ch;
  if (!quantize(c, ch).ok()) { std::printf("%s skipped-config\n", name); return; }
  std::vector<std::vector<typename Fmt::angle_t>> q(K);
  Status st;
  for (int k = 0; k < K; ++k)
    for (double v : qs[k]) q[k].push_back(from_double<typename Fmt::angle_t>(v, st));
  Frames<Fmt, NM> f;
  Jacobian<Fmt, NM> J;
  const int n = c.joints.size();
  timeit(name, sec, [&](int k) {
    Status s;
    forward_kinematics(ch, q[k].data(), f, s);
    jacobian(ch, f, n + 1, -1, J, s);
    return to_double(J.v[0].c[0]) + to_double(f.p[n + 1].c[2]);
  });
}

int main(int argc, char** argv) {
  if (argc < 2) { std::fprintf(stderr, "usage: bench_kin CHAIN.txt [seconds]\n"); return 2; }
  const ChainSpec c = read_spec(argv[1]);
  const double sec = argc > 2 ? std::atof(argv[2]) : 1.0;
  const int n = c.joints.size();
  std::mt19937_64 g(42);
  std::vector<std::vector<double>> qs(K);
  for (auto& q : qs)
    for (const auto& j : c.joints) {
      const double lo = j.limited ? j.lower : -3.14159, hi = j.limited ? j.upper : 3.14159;
      q.push_back(std::uniform_real_distribution<double>(lo, hi)(g));
    }

  // Pinocchio model of the same chain (as tensor_servo/oracle.py builds it).
  pinocchio::Model m;
  pinocchio::JointIndex parent = 0;
  for (int i = 0; i < n; ++i) {
    const auto& j = c.joints[i];
    pinocchio::SE3 pl = se3(j.origin_quat, j.origin_xyz);
    if (i == 0) pl = se3(c.base_quat, c.base_xyz) * pl;
    parent = m.addJoint(parent, joint_model(j), pl, "j" + std::to_string(i));
    m.appendBodyToJoint(parent, pinocchio::Inertia::Identity(), pinocchio::SE3::Identity());
  }
  const auto tool = m.addFrame(pinocchio::Frame("tool", parent, se3(c.tool_quat, c.tool_xyz), pinocchio::OP_FRAME));
  pinocchio::Data d(m);
  std::vector<Eigen::VectorXd> pq(K, Eigen::VectorXd(n));
  for (int k = 0; k < K; ++k)
    for (int i = 0; i < n; ++i) pq[k][i] = qs[k][i] * c.joints[i].scale;
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, n);
  J.setZero();
  timeit("pinocchio", sec, [&](int k) {
    pinocchio::computeFrameJacobian(m, d, pq[k], tool, pinocchio::LOCAL_WORLD_ALIGNED, J);
    return J(0, 0) + d.oMf[tool].translation()[2];
  });
  bench_model<FmtDouble>("tservo-double", c, qs, sec);
  bench_model<FmtDefault>("tservo-default", c, qs, sec);
  bench_model<FmtCompact>("tservo-compact", c, qs, sec);
  return 0;
}
