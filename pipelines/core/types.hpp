#pragma once
// Eigen aliases shared by all pipelines. Doubles for estimation (ARCHITECTURE.md).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace procam {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat34 = Eigen::Matrix<double, 3, 4>;

// std::vector of fixed-size Eigen types: Vector2d/Vector4d need aligned allocation
// before C++17; with C++20 the default allocator is correct.
using Points2 = std::vector<Vec2>;
using Points3 = std::vector<Vec3>;

}  // namespace procam
