#include "chaintube/editor/picking.h"

#include "chaintube/editor/document.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace chaintube::editor {

namespace {

bool rayBox(const Vec3& origin, const Vec3& inverseDirection, const Box& box, double maxT,
            double* entry)
{
    double tmin = 0.0, tmax = maxT;
    for (int axis = 0; axis < 3; ++axis) {
        double t0 = (box.min[axis] - origin[axis]) * inverseDirection[axis];
        double t1 = (box.max[axis] - origin[axis]) * inverseDirection[axis];
        if (t0 > t1) std::swap(t0, t1);
        // NaN (0 · inf) compares false and leaves the interval unchanged: the ray is in the slab.
        if (t0 > tmin) tmin = t0;
        if (t1 < tmax) tmax = t1;
        if (tmin > tmax) return false;
    }
    *entry = tmin;
    return true;
}

Vec3 transformPoint(const Eigen::Matrix4d& m, const Vec3& p)
{
    return (m * p.homogeneous()).head<3>();
}

Vec3 transformVector(const Eigen::Matrix4d& m, const Vec3& v)
{
    return m.block<3, 3>(0, 0) * v;
}

Box transformBox(const Eigen::Matrix4d& m, const Box& box)
{
    Box out;
    if (box.empty()) return out;
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3 p((corner & 1) ? box.max.x() : box.min.x(),
                     (corner & 2) ? box.max.y() : box.min.y(),
                     (corner & 4) ? box.max.z() : box.min.z());
        out.extend(transformPoint(m, p));
    }
    return out;
}

} // namespace

MeshBvh::MeshBvh(const formats::SceneMesh& mesh)
{
    if (mesh.triangleCount() == 0) return;
    try {
        m_collider = MeshCollider::fromArrays(mesh.positions.data(), mesh.vertexCount(),
                                              mesh.indices.data(), mesh.triangleCount() * 3);
    } catch (const InvalidArgument&) {
        return; // non-finite positions or indices out of range: the mesh is not pickable
    }
    const Aabb& bounds = m_collider->localBounds();
    m_bounds.extend(bounds.min);
    m_bounds.extend(bounds.max);
}

bool MeshBvh::closest(const Vec3& point, double maxDistance, Vec3* onMesh) const
{
    if (!m_collider) return false;
    const MeshCollider::Closest found = m_collider->closestToPoint(point, maxDistance);
    if (!found.found) return false;
    *onMesh = found.onMesh;
    return true;
}

bool MeshBvh::intersect(const Vec3& origin, const Vec3& direction, double maxT, Hit* hit) const
{
    if (!m_collider) return false;
    const MeshCollider::RayHit found = m_collider->raycast(origin, direction, maxT);
    hit->trianglesTested = found.trianglesTested;
    if (!found.hit || !(found.t > 1e-9)) return false;
    hit->t = found.t;
    hit->triangle = found.triangle;
    hit->normal = found.normal;
    return true;
}

void ScenePicker::update(const Document& document)
{
    std::string signature;
    for (const auto& [id, scene] : document.scenes())
        signature += id + ":" + std::to_string(reinterpret_cast<std::uintptr_t>(&scene)) + ":" +
                     std::to_string(scene.nodes.size()) + ";";
    if (m_document == &document && m_poseSerial == document.poseSerial() &&
        signature == m_sceneSignature)
        return;
    if (signature != m_sceneSignature) m_bvhs.clear();
    m_document = &document;
    m_poseSerial = document.poseSerial();
    m_sceneSignature = signature;
    m_instances.clear();
    for (const auto& [id, scene] : document.scenes()) {
        for (size_t n = 0; n < scene.nodes.size(); ++n) {
            const formats::SceneNode& node = scene.nodes[n];
            if (node.meshes.empty()) continue;
            const Eigen::Matrix4d world = document.nodeWorldTransform(id, static_cast<int>(n));
            const Eigen::Matrix4d inverse = world.inverse();
            for (int meshIndex : node.meshes) {
                const formats::SceneMesh& mesh = scene.meshes[static_cast<size_t>(meshIndex)];
                if (mesh.triangleCount() == 0) continue;
                auto& bvh = m_bvhs[&mesh];
                if (!bvh) bvh = std::make_unique<MeshBvh>(mesh);
                Instance instance;
                instance.sceneId = id;
                instance.node = static_cast<int>(n);
                instance.bvh = bvh.get();
                instance.worldFromMesh = world;
                instance.meshFromWorld = inverse;
                instance.worldBounds = transformBox(world, bvh->bounds());
                m_instances.push_back(std::move(instance));
            }
        }
    }
}

bool ScenePicker::pick(const Ray& ray, ScenePickHit* hit) const
{
    const Vec3 inverse(1.0 / ray.direction.x(), 1.0 / ray.direction.y(), 1.0 / ray.direction.z());
    double best = std::numeric_limits<double>::max();
    bool found = false;
    for (const Instance& instance : m_instances) {
        double entry = 0.0;
        if (!rayBox(ray.origin, inverse, instance.worldBounds, best, &entry)) continue;
        const Vec3 origin = transformPoint(instance.meshFromWorld, ray.origin);
        const Vec3 direction = transformVector(instance.meshFromWorld, ray.direction);
        MeshBvh::Hit local;
        // Ray parameters are the same in both frames since the direction is transformed too.
        if (!instance.bvh->intersect(origin, direction, best, &local)) continue;
        best = local.t;
        found = true;
        hit->sceneId = instance.sceneId;
        hit->node = instance.node;
        hit->distance = local.t;
        hit->point = ray.origin + local.t * ray.direction;
        // Normals transform with the inverse transpose.
        Vec3 normal = instance.meshFromWorld.block<3, 3>(0, 0).transpose() * local.normal;
        hit->surfaceNormal = normal.allFinite() && normal.norm() > 0;
        if (hit->surfaceNormal) {
            normal.normalize();
            if (normal.dot(ray.direction) > 0) normal = -normal;
        } else {
            normal = -ray.direction;
        }
        hit->normal = normal;
    }
    return found;
}

bool ScenePicker::nearest(const Vec3& point, double maxDistance, Vec3* onSurface) const
{
    double best = maxDistance;
    bool found = false;
    for (const Instance& instance : m_instances) {
        // Boxes farther than the best distance so far hold nothing nearer.
        const Vec3 outside = (instance.worldBounds.min - point)
                                 .cwiseMax(point - instance.worldBounds.max)
                                 .cwiseMax(Vec3::Zero());
        if (!(outside.norm() < best)) continue;
        // The search radius in mesh coordinates: the world radius times the largest stretch
        // of meshFromWorld (bounded by its Frobenius norm).
        const Eigen::Matrix3d toMesh = instance.meshFromWorld.block<3, 3>(0, 0);
        const double localRadius = std::isfinite(best) ? best * toMesh.norm() : best;
        Vec3 local;
        if (!instance.bvh->closest(transformPoint(instance.meshFromWorld, point), localRadius,
                                   &local))
            continue;
        const Vec3 world = transformPoint(instance.worldFromMesh, local);
        const double distance = (world - point).norm();
        if (!(distance < best)) continue;
        best = distance;
        *onSurface = world;
        found = true;
    }
    return found;
}

Box ScenePicker::bounds() const
{
    Box box;
    for (const Instance& instance : m_instances)
        box.extend(instance.worldBounds);
    return box;
}

Box ScenePicker::nodeBounds(const std::string& sceneId, int node) const
{
    Box box;
    if (!m_document) return box;
    const formats::ImportedScene* scene = m_document->scene(sceneId);
    if (!scene) return box;
    for (const Instance& instance : m_instances) {
        if (instance.sceneId != sceneId) continue;
        for (int n = instance.node; n >= 0; n = scene->nodes[static_cast<size_t>(n)].parent)
            if (n == node) {
                box.extend(instance.worldBounds);
                break;
            }
    }
    return box;
}

double raySegmentDistance2(const Ray& ray, const Vec3& a, const Vec3& b, double* t, double* s)
{
    const Vec3 d = b - a;
    const Vec3 w = ray.origin - a;
    const double dd = d.dot(d);
    const double rd = ray.direction.dot(d);
    const double rw = ray.direction.dot(w);
    const double dw = d.dot(w);
    const double denominator = dd - rd * rd; // |r| = 1
    double segment = 0.0;
    if (dd > 1e-300) {
        // Segment parameter of the closest approach of the two lines (|direction| = 1).
        segment = denominator > 1e-12 * dd ? (dw - rd * rw) / denominator : 0.0;
        segment = std::clamp(segment, 0.0, 1.0);
    }
    const Vec3 onSegment = a + segment * d;
    const double along = std::max(0.0, (onSegment - ray.origin).dot(ray.direction));
    *t = along;
    *s = segment;
    return (ray.origin + along * ray.direction - onSegment).squaredNorm();
}

bool pickHose(const Document& document, const Ray& ray, double slackMetres, HosePickHit* hit)
{
    bool found = false;
    double best = std::numeric_limits<double>::max();
    for (const formats::HoseDefinition& definition : document.project().hoses) {
        const Hose* hose = document.hose(definition.id);
        if (!hose) continue;
        const double radius = hose->profile().boundingRadius() + slackMetres;
        for (int segment = 0; segment < hose->segmentCount(); ++segment) {
            const Vec3 a = hose->point(segment), b = hose->point(segment + 1);
            double t = 0.0, s = 0.0;
            if (raySegmentDistance2(ray, a, b, &t, &s) > radius * radius || t >= best) continue;
            best = t;
            found = true;
            hit->hoseId = definition.id;
            hit->point = s < 0.5 ? segment : segment + 1;
            hit->position = hose->point(hit->point);
            hit->distance = t;
        }
    }
    return found;
}

} // namespace chaintube::editor
