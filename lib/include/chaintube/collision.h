// ChainTube — collision with scene objects and clearance analysis (lib/README.md, "Collision").
//
// A scene object that hoses must stay out of is a MeshCollider: a rigid triangle mesh kept in
// a bounding-volume hierarchy built once in the mesh's own frame, placed in the world by a
// Frame that may change every frame (no rebuild). Colliders are shared (std::shared_ptr) by the
// hoses that use them (Hose::setColliders), so moving one collider's frame moves it for every
// hose. Triangles are two-sided: a single triangle is a wall of zero thickness.
//
// A hose keeps outside its colliders with continuous tests of its points (sweepSphere) and of
// its segments (sweepSegment), from its previous shape and relative to each moved collider, so
// a 2 mm plate, a plate of two triangles or a knife edge moved through it at 2 m/s at 90 Hz
// pushes it along or round the edge instead of crossing it (lib/README.md, "Collision").
//
// Error policy: building a collider validates its arrays and throws InvalidArgument naming the
// field; queries never throw and return finite values only.
#pragma once

#include "chaintube/types.h"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace chaintube {

class Hose;

/// Axis-aligned box (metres). Empty when min > max (the default).
struct Aabb
{
    Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());
    bool empty() const { return (min.array() > max.array()).any(); }
    void extend(const Vec3& p)
    {
        min = min.cwiseMin(p);
        max = max.cwiseMax(p);
    }
    void extend(const Aabb& box)
    {
        min = min.cwiseMin(box.min);
        max = max.cwiseMax(box.max);
    }
    /// Whether the two closed boxes share a point (boxes that only touch overlap).
    bool overlaps(const Aabb& box) const
    {
        return (min.array() <= box.max.array()).all() && (box.min.array() <= max.array()).all();
    }
};

/// A rigid triangle mesh that hoses stay outside of.
class MeshCollider
{
public:
    /// Builds the collider from flat arrays in the mesh's local frame (metres):
    /// `positions` holds vertexCount × 3 floats (x, y, z per vertex), `indices` holds
    /// indexCount entries, three per triangle, each < vertexCount. The frame is rigid: bake a
    /// node's scale or shear into the positions. Degenerate (zero-area) triangles still
    /// collide as segments or points. Throws InvalidArgument naming the field when positions or
    /// indices are null with a non-zero count, vertexCount or indexCount is 0, indexCount is
    /// not a multiple of 3, an index is out of range, a position is not finite, or the frame is
    /// not finite. O(n log n) for n triangles. Degenerate meshes (many triangles at one spot,
    /// long thin strips, all coplanar) are answered exactly like any other: the hierarchy always
    /// halves its triangles (≤ 4 per leaf, depth ⌈log2(n / 4)⌉) and its traversal never drops a
    /// subtree; coincident triangles only cost time.
    static std::shared_ptr<MeshCollider> fromArrays(const float* positions, std::size_t vertexCount,
                                                    const std::uint32_t* indices,
                                                    std::size_t indexCount,
                                                    const Frame& frame = Frame::identity());
    /// Same, from double positions (one Vec3 per vertex).
    static std::shared_ptr<MeshCollider> fromArrays(const std::vector<Vec3>& positions,
                                                    const std::vector<std::uint32_t>& indices,
                                                    const Frame& frame = Frame::identity());

    /// Places the mesh in the world: world = frame.apply(local). Cheap (no rebuild). A frame
    /// that is not finite is refused: returns false and keeps the previous frame.
    bool setFrame(const Frame& frame);
    const Frame& frame() const { return m_frame; }
    /// Incremented by every accepted setFrame(); hoses use it to know a collider moved.
    std::uint64_t revision() const { return m_revision; }

    int triangleCount() const { return static_cast<int>(m_triangles.size()); }
    /// Bounds of the triangles in the local frame, and the world box around them.
    const Aabb& localBounds() const { return m_localBounds; }
    Aabb worldBounds() const;

    /// Closest point of the mesh to a query (point or segment), world metres.
    struct Closest
    {
        bool found = false;          ///< false: nothing within maxDistance (the other fields unset)
        double distance = 0.0;       ///< ≥ 0
        Vec3 onMesh = Vec3::Zero();  ///< world point on the triangles
        Vec3 onQuery = Vec3::Zero(); ///< world point on the query (the point, or on the segment)
        /// World, unit: from onMesh towards onQuery; where they coincide (a segment crossing
        /// the mesh), the triangle's normal (as wound).
        Vec3 normal = Vec3::UnitY();
        double segmentParameter = 0.0; ///< segment queries: onQuery = a + s (b − a), s ∈ [0, 1]
        int triangle = -1;             ///< index of the triangle (in the order given)
    };
    /// Closest point of the mesh to `point` among points nearer than maxDistance.
    Closest closestToPoint(const Vec3& point,
                           double maxDistance = std::numeric_limits<double>::infinity()) const;
    /// Closest pair between the segment a–b and the mesh, nearer than maxDistance. A segment
    /// crossing a triangle has distance 0.
    Closest closestToSegment(const Vec3& a, const Vec3& b,
                             double maxDistance = std::numeric_limits<double>::infinity()) const;

    /// Continuous test of a sphere of `radius` (metres, ≥ 0) moving in a straight line from
    /// `from` to `to` (world): the first contact. Contacts the sphere already has at `from`
    /// and does not move deeper into are ignored, so a sphere resting on a surface can slide
    /// along it or lift off. A zero-thickness wall or a gap narrower than 2·radius stops it.
    struct Sweep
    {
        bool hit = false;
        double fraction = 1.0;       ///< of the move, in [0, 1], at first contact
        Vec3 normal = Vec3::UnitY(); ///< world, unit, from the contact towards the centre
        int triangle = -1;
    };
    Sweep sweepSphere(const Vec3& from, const Vec3& to, double radius) const;

    /// Closest-segment queries a sweepSegment() call makes at most by default.
    static constexpr int kSegmentSweepQueries = 16;
    /// Continuous test of the segment a–b whose ends move in straight lines from a0, b0 to
    /// a1, b1 (world), by conservative advancement: each closestToSegment() query (within the
    /// distance the rest of the move can cover) advances the move by the gap over the fastest
    /// end's travel, so no point of the segment gets nearer than `radius` (metres, ≥ 0) before
    /// `fraction`. A segment already nearer than `radius` at the start (or within 4 % beyond it,
    /// where an earlier sweep stopped it) keeps half its starting distance, so it can move off or
    /// along; one crossing the mesh at the start is not stopped. At most `maxQueries`
    /// queries (≥ 1): a move still not cleared then stops where it got (`bounded`), so the
    /// cost of a call is bounded and what it returns is always safe.
    struct SegmentSweep
    {
        bool hit = false;            ///< stopped before the end of the move
        bool bounded = false;        ///< stopped by maxQueries rather than a contact
        double fraction = 1.0;       ///< of the move, in [0, 1]: safe up to here
        Vec3 normal = Vec3::UnitY(); ///< world, unit, from the mesh towards the segment
        int queries = 0;             ///< closestToSegment() queries made
    };
    SegmentSweep sweepSegment(const Vec3& a0, const Vec3& b0, const Vec3& a1, const Vec3& b1,
                              double radius, int maxQueries = kSegmentSweepQueries) const;

    /// First triangle hit by the ray origin + t·direction with t in (0, maxT) (two-sided).
    struct RayHit
    {
        bool hit = false;
        double t = 0.0;
        Vec3 normal = Vec3::UnitY(); ///< world, unit, facing the ray origin
        int triangle = -1;
        /// How many triangles the query tested, hit or not (the hierarchy's work: a few for a
        /// ray through a large mesh, not the mesh).
        int trianglesTested = 0;
    };
    RayHit raycast(const Vec3& origin, const Vec3& direction,
                   double maxT = std::numeric_limits<double>::infinity()) const;

    struct Triangle
    {
        Vec3 a, b, c; ///< local metres
    };
    struct Node
    {
        Aabb box;
        int first = 0; ///< leaf: first index into the triangle order; inner: left child
        int count = 0; ///< leaf: number of triangles; inner: 0 (right child = first + 1)
    };

private:
    MeshCollider() = default;
    void build();
    /// Depth-first traversal shared by every query (mesh_collider.cpp documents the visitor).
    template <class Visitor> void traverse(Visitor& visitor) const;
    std::vector<Triangle> m_triangles; ///< in the BVH's leaf order
    std::vector<int> m_originalIndex;  ///< triangle index as given, per stored triangle
    std::vector<Node> m_nodes;
    Aabb m_localBounds;
    int m_depth = 0; ///< deepest node (root 0): the traversal stack needs depth + 1 entries
    Frame m_frame;
    std::uint64_t m_revision = 1;
};

/// How a hose with colliders keeps outside them (Hose::setColliders).
struct CollisionOptions
{
    /// Metres. After an update that is not blocked, the hose surface is inside no collider by
    /// more than this. > 0.
    double tolerance = 1e-4;
    /// Residual the contact rounds aim for on the length band (relative) and bend limits
    /// (radians) when contacts move points the exact solver placed. > 0.
    double constraintTolerance = 1e-6;
    /// Bound on the contact rounds per update (each O(points) plus the nearby queries). ≥ 1.
    int maxRounds = 48;
};

/// Where a hose comes closest to a scene object.
struct Clearance
{
    bool found = false; ///< false: the object is farther than the search distance, or empty
    /// Hose surface to the nearest triangle (metres): axis distance − the hose's outer radius;
    /// negative when the hose is inside the object by that much.
    double distance = 0.0;
    int segment = -1;           ///< axis segment (points segment … segment + 1) where it occurs
    int axisPoint = -1;         ///< the axis point nearest to it (segment or segment + 1)
    Vec3 onAxis = Vec3::Zero(); ///< world point on the hose axis
    Vec3 onSurface = Vec3::Zero(); ///< world point on the hose surface towards the object
    Vec3 onObject = Vec3::Zero();  ///< world point on the object's triangles
    int triangle = -1;
};

/// Minimum distance between the hose's surface (a tube of outerRadius() round its axis
/// polyline) and the collider's triangles, and where it occurs. Objects whose surface distance
/// exceeds searchDistance are not searched exhaustively: found is then false.
Clearance clearance(const Hose& hose, const MeshCollider& collider,
                    double searchDistance = std::numeric_limits<double>::infinity());

} // namespace chaintube
