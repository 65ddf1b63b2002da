#include "chaintube/editor/camera.h"

#include <algorithm>
#include <cmath>

namespace chaintube::editor {

Vec3 Camera::forward() const
{
    // yaw 0, pitch 0 looks along −Z.
    const double cp = std::cos(pitch);
    return Vec3(-std::sin(yaw) * cp, std::sin(pitch), -std::cos(yaw) * cp).normalized();
}

Vec3 Camera::eye() const
{
    return target - distance * forward();
}

Vec3 Camera::right() const
{
    return forward().cross(Vec3::UnitY()).normalized();
}

Vec3 Camera::up() const
{
    return right().cross(forward()).normalized();
}

Eigen::Matrix4d Camera::view() const
{
    const Vec3 f = forward(), r = right(), u = up(), e = eye();
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.block<1, 3>(0, 0) = r.transpose();
    m.block<1, 3>(1, 0) = u.transpose();
    m.block<1, 3>(2, 0) = -f.transpose();
    m(0, 3) = -r.dot(e);
    m(1, 3) = -u.dot(e);
    m(2, 3) = f.dot(e);
    return m;
}

Eigen::Matrix4d Camera::projection(double aspect) const
{
    const double nearPlane = std::max(1e-4, distance * 0.01);
    const double farPlane = distance * 100.0 + 10.0;
    const double f = 1.0 / std::tan(fieldOfViewY / 2.0);
    Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
    m(0, 0) = f / std::max(aspect, 1e-6);
    m(1, 1) = f;
    m(2, 2) = (farPlane + nearPlane) / (nearPlane - farPlane);
    m(2, 3) = 2.0 * farPlane * nearPlane / (nearPlane - farPlane);
    m(3, 2) = -1.0;
    return m;
}

Ray Camera::rayThrough(double x, double y, int width, int height) const
{
    const double aspect = double(width) / std::max(height, 1);
    const double ndcX = 2.0 * x / std::max(width, 1) - 1.0;
    const double ndcY = 1.0 - 2.0 * y / std::max(height, 1);
    const double t = std::tan(fieldOfViewY / 2.0);
    Ray ray;
    ray.origin = eye();
    ray.direction = (forward() + right() * ndcX * t * aspect + up() * ndcY * t).normalized();
    return ray;
}

bool Camera::project(const Vec3& world, int width, int height, Eigen::Vector2d* pixel) const
{
    const Eigen::Vector4d clip =
        projection(double(width) / std::max(height, 1)) * view() * world.homogeneous();
    if (clip.w() <= 1e-12) return false;
    const double ndcX = clip.x() / clip.w(), ndcY = clip.y() / clip.w();
    *pixel = Eigen::Vector2d((ndcX + 1.0) * 0.5 * width, (1.0 - ndcY) * 0.5 * height);
    return true;
}

void Camera::orbit(double dxPixels, double dyPixels)
{
    yaw -= dxPixels * 0.01;
    pitch = std::clamp(pitch - dyPixels * 0.01, -1.55, 1.55);
}

void Camera::pan(double dxPixels, double dyPixels, int viewportHeight)
{
    const double metresPerPixel =
        2.0 * distance * std::tan(fieldOfViewY / 2.0) / std::max(viewportHeight, 1);
    target += (-dxPixels * right() + dyPixels * up()) * metresPerPixel;
}

void Camera::zoom(double steps)
{
    distance = std::max(1e-3, distance * std::pow(0.85, steps));
}

void Camera::frame(const Box& box)
{
    if (box.empty()) return;
    target = box.centre();
    const double radius = std::max(box.radius(), 0.01);
    distance = radius / std::sin(fieldOfViewY / 2.0) * 0.9;
}

} // namespace chaintube::editor
