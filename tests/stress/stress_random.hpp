#pragma once
// Random inputs shared by the primitive stress tests.
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "core/types.hpp"

namespace procam::stress {

constexpr double kEps = std::numeric_limits<double>::epsilon();

struct Rng {
  std::mt19937_64 gen;
  explicit Rng(std::uint64_t seed) : gen(seed) {}

  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(gen);
  }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(gen); }
  double logUniform(double lo_exp10, double hi_exp10) {
    return std::pow(10.0, uniform(lo_exp10, hi_exp10));
  }
  bool chance(double p) { return uniform(0, 1) < p; }
  Vec3 unit() {
    std::normal_distribution<double> g;
    Vec3 v(g(gen), g(gen), g(gen));
    while (v.norm() < 1e-3) v = Vec3(g(gen), g(gen), g(gen));
    return v.normalized();
  }
  Vec3 inCube(double half) {
    return Vec3(uniform(-half, half), uniform(-half, half), uniform(-half, half));
  }
  Mat3 rotation() {
    std::normal_distribution<double> g;
    return Eigen::Quaterniond(g(gen), g(gen), g(gen), g(gen)).normalized().toRotationMatrix();
  }
  // Coordinates either near the origin or 1e4 away (pixels/mm of a real rig).
  Vec3 offset() { return chance(0.5) ? Vec3(Vec3::Zero()) : Vec3(1e4 * unit()); }
  // A non-finite value of a random kind.
  double bad() {
    const int k = integer(0, 2);
    return k == 0 ? std::numeric_limits<double>::quiet_NaN()
                  : (k == 1 ? std::numeric_limits<double>::infinity()
                            : -std::numeric_limits<double>::infinity());
  }
};

inline void report(const char* what, long cases) {
  std::printf("[stress] %s: %ld cases\n", what, cases);
}

}  // namespace procam::stress
