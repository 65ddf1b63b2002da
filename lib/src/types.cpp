#include "chaintube/types.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace chaintube {

bool isFiniteFrame(const Frame& frame)
{
    return frame.rotation.coeffs().allFinite() && frame.translation.allFinite() &&
           std::abs(frame.rotation.norm() - 1.0) < 1e-6;
}

Frame rigidPart(const Eigen::Matrix4d& transform)
{
    Frame frame;
    frame.translation = transform.block<3, 1>(0, 3);
    const Eigen::Matrix3d linear = transform.block<3, 3>(0, 0);
    if (!linear.allFinite()) return frame;
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Vector3d singular = svd.singularValues();
    if (!(singular(2) > 1e-12 * std::max(1.0, singular(0)))) return frame;
    Eigen::Matrix3d u = svd.matrixU();
    if ((u * svd.matrixV().transpose()).determinant() < 0) u.col(2) = -u.col(2);
    frame.rotation = Quat(Eigen::Quaterniond(u * svd.matrixV().transpose()).normalized());
    return frame;
}

} // namespace chaintube
