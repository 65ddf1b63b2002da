// ChainTube — basic types and the library's error policy.
//
// Error policy (lib/README.md, "Error policy"):
//  * Set-up functions (building a hose, a profile, a material, attaching) validate every
//    argument and throw chaintube::InvalidArgument whose message names the parameter and
//    what was expected. They never assert on caller input in release builds.
//  * Per-frame functions (grab, moving attachments, updating a scene) never throw: they
//    return an UpdateResult whose status the caller must look at. Invalid input (NaN or Inf,
//    an index out of range, grabbing a fixed point) is rejected with Status::InvalidInput and
//    leaves the hose unchanged.
//  * No NaN or Inf ever leaves the library: every output is finite.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <stdexcept>
#include <string>

namespace chaintube {

/// Scalar of the solver. Vertex buffers handed to renderers are float.
using Real = double;
using Vec2 = Eigen::Matrix<double, 2, 1, Eigen::DontAlign>;
using Vec3 = Eigen::Matrix<double, 3, 1, Eigen::DontAlign>;
using Quat = Eigen::Quaternion<double, Eigen::DontAlign>;
using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::DontAlign>;

/// A rigid frame: world = rotation * local + translation. Rotation is orthonormal.
struct Frame
{
    Quat rotation = Quat::Identity();
    Vec3 translation = Vec3::Zero();

    static Frame identity() { return {}; }
    Vec3 apply(const Vec3& local) const { return rotation * local + translation; }
    Vec3 applyInverse(const Vec3& world) const
    {
        return rotation.conjugate() * (world - translation);
    }
    Frame operator*(const Frame& other) const
    {
        return {rotation * other.rotation, rotation * other.translation + translation};
    }
    Frame inverse() const
    {
        const Quat inv = rotation.conjugate();
        return {inv, -(inv * translation)};
    }
};

/// Root of every exception the library throws.
class Error : public std::runtime_error
{
public:
    using std::runtime_error::runtime_error;
};

/// A caller passed a value outside the documented domain of a set-up function.
class InvalidArgument : public Error
{
public:
    using Error::Error;
};

/// True if every component is finite (no NaN, no Inf).
template <typename Derived> bool allFinite(const Eigen::MatrixBase<Derived>& value)
{
    return value.allFinite();
}
bool isFiniteFrame(const Frame& frame);

/// Rigid part of an affine transform (column vectors: world = M · local): its translation, and
/// the rotation nearest to its 3×3 block (polar decomposition; a reflection is turned into a
/// rotation by flipping the axis of the smallest singular value). A block that is not finite, or
/// whose smallest singular value is not above 1e-12 × max(1, largest), gives the identity
/// rotation. The translation is taken as it is (a non-finite one stays non-finite, so that
/// Hose::attach / moveAttachment refuse the frame). The frame scene nodes give attachments and
/// colliders (formats, the runtime).
Frame rigidPart(const Eigen::Matrix4d& transform);

} // namespace chaintube
