#pragma once
// Basic linear-algebra types. All lengths in metres unless a name says otherwise.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rocklab::geometry {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

}  // namespace rocklab::geometry
