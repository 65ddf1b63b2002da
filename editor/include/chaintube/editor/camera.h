// ChainTube editor — the orbit camera of the viewport (no OpenGL, no widgets).
#pragma once

#include "chaintube/types.h"

#include <Eigen/Core>

namespace chaintube::editor {

/// A ray in world coordinates (direction unit length).
struct Ray
{
    Vec3 origin = Vec3::Zero();
    Vec3 direction = Vec3(0, 0, -1);
};

/// Axis-aligned box (world metres). Empty when min > max.
struct Box
{
    Vec3 min = Vec3::Constant(1e300);
    Vec3 max = Vec3::Constant(-1e300);
    bool empty() const { return (min.array() > max.array()).any(); }
    void extend(const Vec3& p)
    {
        min = min.cwiseMin(p);
        max = max.cwiseMax(p);
    }
    void extend(const Box& b)
    {
        if (!b.empty()) {
            extend(b.min);
            extend(b.max);
        }
    }
    Vec3 centre() const { return 0.5 * (min + max); }
    double radius() const { return empty() ? 0.0 : 0.5 * (max - min).norm(); }
};

/// Orbit camera: looks at `target` from `distance` metres, rotated by yaw (about +Y) and
/// pitch (radians, ±89°). Perspective with a vertical field of view. +Y is up.
class Camera
{
public:
    Vec3 target = Vec3::Zero();
    double distance = 2.0; ///< metres > 0
    double yaw = 0.6;      ///< radians about +Y
    double pitch = -0.45;  ///< radians, negative looks down
    double fieldOfViewY = 45.0 * 3.14159265358979323846 / 180.0;

    /// World position of the eye.
    Vec3 eye() const;
    /// Unit vector from the eye to the target.
    Vec3 forward() const;
    Vec3 right() const;
    Vec3 up() const;
    /// View matrix (world → eye), column vectors.
    Eigen::Matrix4d view() const;
    /// Projection for a viewport of aspect width/height; near/far follow the distance.
    Eigen::Matrix4d projection(double aspect) const;
    /// Ray through pixel (x, y) of a width × height viewport (y down, pixel centres at +0.5).
    Ray rayThrough(double x, double y, int width, int height) const;
    /// Window coordinates (x right, y down, pixels) of a world point; false if behind the eye.
    bool project(const Vec3& world, int width, int height, Eigen::Vector2d* pixel) const;

    /// Orbit by pixel deltas (0.01 rad per pixel).
    void orbit(double dxPixels, double dyPixels);
    /// Pan by pixel deltas in a viewport of the given height (the target moves in the view
    /// plane so that a point at the target follows the mouse).
    void pan(double dxPixels, double dyPixels, int viewportHeight);
    /// Zoom by wheel steps (positive = closer); the distance changes by 15 % per step.
    void zoom(double steps);
    /// Looks at a box so that it fills the view.
    void frame(const Box& box);
};

} // namespace chaintube::editor
