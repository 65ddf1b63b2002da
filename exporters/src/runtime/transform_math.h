// Internal: affine ↔ TRS conversions shared by the exporter and the runtime.
#pragma once

#include "chaintube/export/rig_descriptor.h"

#include <Eigen/Dense>

namespace chaintube::rig::detail {

using Affine = Eigen::Matrix4d;

/// T · R · S as a 4×4 matrix (glTF's node transform).
inline Affine matrixOf(const NodeTransform& trs)
{
    Affine m = Affine::Identity();
    m.topLeftCorner<3, 3>() = Eigen::Quaterniond(trs.rotation).normalized().toRotationMatrix() *
                              Eigen::Vector3d(trs.scale).asDiagonal();
    m.topRightCorner<3, 1>() = Eigen::Vector3d(trs.translation);
    return m;
}

inline Affine matrixOf(const Frame& frame)
{
    Affine m = Affine::Identity();
    m.topLeftCorner<3, 3>() = Eigen::Quaterniond(frame.rotation).toRotationMatrix();
    m.topRightCorner<3, 1>() = Eigen::Vector3d(frame.translation);
    return m;
}

/// decompose(): a 3 × 3 block whose columns are this near orthonormal is a rotation as it is
/// (rounding only; the quaternion is normalised).
constexpr double kOrthonormal = 1e-12;

/// Splits an affine matrix into T · R · S with S diagonal (positive; a reflection flips the
/// sign of the smallest scale). Returns false if the 3×3 block is not a rotation times a
/// diagonal scale within `tolerance` (relative), i.e. it has shear; trs is then a best fit.
inline bool decompose(const Affine& m, NodeTransform& trs, double tolerance = 1e-6)
{
    const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
    Eigen::Vector3d scale(linear.col(0).norm(), linear.col(1).norm(), linear.col(2).norm());
    trs.translation = m.topRightCorner<3, 1>();
    if (!(scale.minCoeff() > 0.0)) {
        trs.rotation = Quat::Identity();
        trs.scale = Vec3::Ones();
        return false;
    }
    Eigen::Matrix3d rotation = linear * scale.cwiseInverse().asDiagonal();
    if (rotation.determinant() < 0.0) {
        Eigen::Index smallest = 0;
        scale.minCoeff(&smallest);
        scale(smallest) = -scale(smallest);
        rotation.col(smallest) = -rotation.col(smallest);
    }
    const double orthogonality =
        (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    // Re-orthonormalise where the columns' angles are off by more than rounding (the columns
    // are unit length): the nearest rotation, by the SVD.
    if (orthogonality > kOrthonormal) {
        Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
        rotation = svd.matrixU() * svd.matrixV().transpose();
    }
    trs.rotation = Quat(Eigen::Quaterniond(rotation).normalized());
    trs.scale = scale;
    return orthogonality <= tolerance;
}

} // namespace chaintube::rig::detail
