// ChainTube editor — ray picking against scene triangles and hoses.
//
// Scene meshes get one bounding-volume hierarchy each, built once in the mesh's own frame
// (the core library's chaintube::MeshCollider, which hose collision uses too: median split,
// ≤ 4 triangles per leaf). A pick transforms the ray into each
// instance's frame (node world transform with the document's pose applied), so moving a part
// never rebuilds a hierarchy. Building is O(n log n) for n triangles; a pick tests only the
// few triangles along the ray (MeshBvh::Hit::trianglesTested reports how many).
#pragma once

#include "chaintube/collision.h"
#include "chaintube/editor/camera.h"
#include "chaintube/formats/scene.h"

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace chaintube::editor {

class Document;

/// Ray–triangle hierarchy of one mesh (mesh-local coordinates, float data copied in double).
class MeshBvh
{
public:
    explicit MeshBvh(const formats::SceneMesh& mesh);

    struct Hit
    {
        double t = 0.0;          ///< ray parameter (distance if the direction is unit length)
        int triangle = -1;       ///< index into the mesh's triangles
        Vec3 normal;             ///< geometric normal, facing the ray origin, unit length
        int trianglesTested = 0; ///< the hierarchy's work for this query (MeshCollider::RayHit)
    };
    /// Closest hit with t in (1e-9, maxT); both faces count. Returns false if none.
    bool intersect(const Vec3& origin, const Vec3& direction, double maxT, Hit* hit) const;
    /// Closest point of the mesh to `point` (mesh coordinates) nearer than maxDistance; false
    /// if none.
    bool closest(const Vec3& point, double maxDistance, Vec3* onMesh) const;
    /// Bounds in mesh coordinates.
    const Box& bounds() const { return m_bounds; }
    int triangleCount() const { return m_collider ? m_collider->triangleCount() : 0; }

private:
    std::shared_ptr<MeshCollider> m_collider; ///< null for a mesh without triangles
    Box m_bounds;
};

/// Result of a scene pick.
struct ScenePickHit
{
    std::string sceneId;
    int node = -1;
    Vec3 point = Vec3::Zero(); ///< world metres
    /// World, unit, facing the ray origin. surfaceNormal false: the mesh normal brought into the
    /// world came out zero or not finite, and this is the reverse of the ray's direction.
    Vec3 normal = Vec3::UnitY();
    bool surfaceNormal = true;
    double distance = 0.0; ///< along the ray (metres)
};

/// Picks against every mesh instance of a document's scenes, with its pose.
class ScenePicker
{
public:
    /// Builds (or reuses) the per-mesh hierarchies and the instance list if the document's
    /// scenes or pose changed since the last call. Cheap when nothing changed.
    void update(const Document& document);
    /// Closest hit along the ray, or false.
    bool pick(const Ray& ray, ScenePickHit* hit) const;
    /// Nearest point of any mesh instance to `point` (world metres) among those nearer than
    /// maxDistance; false if none. Each mesh is searched in its own frame: under a non-uniform
    /// scale the point found is near, not always exactly, the nearest in the world.
    bool nearest(const Vec3& point, double maxDistance, Vec3* onSurface) const;
    /// World bounds of everything (empty if no scene).
    Box bounds() const;
    /// World bounds of one node's meshes and its descendants' (empty if none).
    Box nodeBounds(const std::string& sceneId, int node) const;

private:
    struct Instance
    {
        std::string sceneId;
        int node = -1;
        const MeshBvh* bvh = nullptr;
        Eigen::Matrix4d worldFromMesh;
        Eigen::Matrix4d meshFromWorld;
        Box worldBounds;
    };
    std::map<const formats::SceneMesh*, std::unique_ptr<MeshBvh>> m_bvhs;
    std::vector<Instance> m_instances;
    const Document* m_document = nullptr;
    std::uint64_t m_poseSerial = 0;
    std::string m_sceneSignature;
};

/// Result of a hose pick.
struct HosePickHit
{
    std::string hoseId;
    int point = -1;               ///< nearest axis point to the hit
    Vec3 position = Vec3::Zero(); ///< that axis point (world)
    double distance = 0.0;        ///< along the ray to the closest approach
};

/// Picks the live hoses of a document: a segment counts as hit when the ray passes within
/// the hose's bounding radius plus `slackMetres` of its axis. Returns the nearest one.
bool pickHose(const Document& document, const Ray& ray, double slackMetres, HosePickHit* hit);

/// Closest points between a ray and a segment [a, b]: returns the squared distance and the
/// ray parameter t (≥ 0) and segment parameter s ∈ [0, 1].
double raySegmentDistance2(const Ray& ray, const Vec3& a, const Vec3& b, double* t, double* s);

} // namespace chaintube::editor
