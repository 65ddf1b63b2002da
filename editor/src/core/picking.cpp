#include "chaintube/editor/picking.h"

#include "chaintube/editor/document.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace chaintube::editor {

namespace {

constexpr int kLeafSize = 4;

bool rayBox(const Vec3& origin, const Vec3& inverseDirection, const Box& box, double maxT,
            double* entry)
{
    double tmin = 0.0, tmax = maxT;
    for (int axis = 0; axis < 3; ++axis) {
        double t0 = (box.min[axis] - origin[axis]) * inverseDirection[axis];
        double t1 = (box.max[axis] - origin[axis]) * inverseDirection[axis];
        if (t0 > t1)
            std::swap(t0, t1);
        // NaN (0 · inf) compares false and leaves the interval unchanged: the ray is in the slab.
        if (t0 > tmin)
            tmin = t0;
        if (t1 < tmax)
            tmax = t1;
        if (tmin > tmax)
            return false;
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
    if (box.empty())
        return out;
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
    const size_t triangleCount = mesh.triangleCount();
    m_triangles.reserve(triangleCount);
    std::vector<Vec3> centroids;
    centroids.reserve(triangleCount);
    auto vertex = [&](std::uint32_t index) {
        return Vec3(mesh.positions[3 * index], mesh.positions[3 * index + 1],
                    mesh.positions[3 * index + 2]);
    };
    for (size_t t = 0; t < triangleCount; ++t) {
        Triangle tri{vertex(mesh.indices[3 * t]), vertex(mesh.indices[3 * t + 1]),
                     vertex(mesh.indices[3 * t + 2])};
        centroids.push_back((tri.a + tri.b + tri.c) / 3.0);
        m_triangles.push_back(tri);
    }
    m_order.resize(triangleCount);
    std::iota(m_order.begin(), m_order.end(), 0);
    m_nodes.reserve(2 * triangleCount / kLeafSize + 2);
    if (triangleCount > 0) {
        m_nodes.emplace_back();
        build(0, static_cast<int>(triangleCount), centroids);
        m_bounds = m_nodes[0].box;
    }
}

int MeshBvh::build(int first, int count, std::vector<Vec3>& centroids)
{
    // Iterative over a stack to stay safe on degenerate (very deep) inputs.
    struct Task
    {
        int node, first, count;
    };
    std::vector<Task> stack{{0, first, count}};
    while (!stack.empty()) {
        const Task task = stack.back();
        stack.pop_back();
        Box box, centroidBox;
        for (int i = task.first; i < task.first + task.count; ++i) {
            const Triangle& tri = m_triangles[static_cast<size_t>(m_order[static_cast<size_t>(i)])];
            box.extend(tri.a);
            box.extend(tri.b);
            box.extend(tri.c);
            centroidBox.extend(centroids[static_cast<size_t>(m_order[static_cast<size_t>(i)])]);
        }
        m_nodes[static_cast<size_t>(task.node)].box = box;
        const Vec3 extent = centroidBox.max - centroidBox.min;
        int axis = 0;
        extent.maxCoeff(&axis);
        if (task.count <= kLeafSize || extent[axis] <= 0.0) {
            m_nodes[static_cast<size_t>(task.node)].first = task.first;
            m_nodes[static_cast<size_t>(task.node)].count = task.count;
            continue;
        }
        const int half = task.count / 2;
        auto begin = m_order.begin() + task.first;
        std::nth_element(begin, begin + half, begin + task.count, [&](int a, int b) {
            return centroids[static_cast<size_t>(a)][axis] < centroids[static_cast<size_t>(b)][axis];
        });
        const int left = static_cast<int>(m_nodes.size());
        m_nodes.emplace_back();
        m_nodes.emplace_back();
        m_nodes[static_cast<size_t>(task.node)].first = left;
        m_nodes[static_cast<size_t>(task.node)].count = 0;
        stack.push_back({left, task.first, half});
        stack.push_back({left + 1, task.first + half, task.count - half});
    }
    return 0;
}

bool MeshBvh::intersect(const Vec3& origin, const Vec3& direction, double maxT, Hit* hit) const
{
    if (m_nodes.empty())
        return false;
    const Vec3 inverse(1.0 / direction.x(), 1.0 / direction.y(), 1.0 / direction.z());
    double best = maxT;
    int bestTriangle = -1;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = m_nodes[static_cast<size_t>(stack[--top])];
        double entry = 0.0;
        if (!rayBox(origin, inverse, node.box, best, &entry))
            continue;
        if (node.count > 0) {
            for (int i = node.first; i < node.first + node.count; ++i) {
                const int index = m_order[static_cast<size_t>(i)];
                const Triangle& tri = m_triangles[static_cast<size_t>(index)];
                // Möller–Trumbore, both faces.
                const Vec3 e1 = tri.b - tri.a, e2 = tri.c - tri.a;
                const Vec3 p = direction.cross(e2);
                const double det = e1.dot(p);
                if (std::abs(det) < 1e-300)
                    continue;
                const double invDet = 1.0 / det;
                const Vec3 s = origin - tri.a;
                const double u = s.dot(p) * invDet;
                if (u < 0.0 || u > 1.0)
                    continue;
                const Vec3 q = s.cross(e1);
                const double v = direction.dot(q) * invDet;
                if (v < 0.0 || u + v > 1.0)
                    continue;
                const double t = e2.dot(q) * invDet;
                if (t > 1e-9 && t < best) {
                    best = t;
                    bestTriangle = index;
                }
            }
        } else if (top + 2 <= 128) {
            stack[top++] = node.first;
            stack[top++] = node.first + 1;
        }
    }
    if (bestTriangle < 0)
        return false;
    const Triangle& tri = m_triangles[static_cast<size_t>(bestTriangle)];
    Vec3 normal = (tri.b - tri.a).cross(tri.c - tri.a);
    if (normal.norm() > 0)
        normal.normalize();
    else
        normal = Vec3::UnitY();
    if (normal.dot(direction) > 0)
        normal = -normal;
    hit->t = best;
    hit->triangle = bestTriangle;
    hit->normal = normal;
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
    if (signature != m_sceneSignature)
        m_bvhs.clear();
    m_document = &document;
    m_poseSerial = document.poseSerial();
    m_sceneSignature = signature;
    m_instances.clear();
    for (const auto& [id, scene] : document.scenes()) {
        for (size_t n = 0; n < scene.nodes.size(); ++n) {
            const formats::SceneNode& node = scene.nodes[n];
            if (node.meshes.empty())
                continue;
            const Eigen::Matrix4d world = document.nodeWorldTransform(id, static_cast<int>(n));
            const Eigen::Matrix4d inverse = world.inverse();
            for (int meshIndex : node.meshes) {
                const formats::SceneMesh& mesh = scene.meshes[static_cast<size_t>(meshIndex)];
                if (mesh.triangleCount() == 0)
                    continue;
                auto& bvh = m_bvhs[&mesh];
                if (!bvh)
                    bvh = std::make_unique<MeshBvh>(mesh);
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
    const Vec3 inverse(1.0 / ray.direction.x(), 1.0 / ray.direction.y(),
                       1.0 / ray.direction.z());
    double best = std::numeric_limits<double>::max();
    bool found = false;
    for (const Instance& instance : m_instances) {
        double entry = 0.0;
        if (!rayBox(ray.origin, inverse, instance.worldBounds, best, &entry))
            continue;
        const Vec3 origin = transformPoint(instance.meshFromWorld, ray.origin);
        const Vec3 direction = transformVector(instance.meshFromWorld, ray.direction);
        MeshBvh::Hit local;
        // Ray parameters are the same in both frames since the direction is transformed too.
        if (!instance.bvh->intersect(origin, direction, best, &local))
            continue;
        best = local.t;
        found = true;
        hit->sceneId = instance.sceneId;
        hit->node = instance.node;
        hit->distance = local.t;
        hit->point = ray.origin + local.t * ray.direction;
        // Normals transform with the inverse transpose.
        Vec3 normal = instance.meshFromWorld.block<3, 3>(0, 0).transpose() * local.normal;
        if (normal.norm() > 0)
            normal.normalize();
        else
            normal = Vec3::UnitY();
        if (normal.dot(ray.direction) > 0)
            normal = -normal;
        hit->normal = normal;
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
    if (!m_document)
        return box;
    const formats::ImportedScene* scene = m_document->scene(sceneId);
    if (!scene)
        return box;
    for (const Instance& instance : m_instances) {
        if (instance.sceneId != sceneId)
            continue;
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
        if (!hose)
            continue;
        const double radius = hose->profile().boundingRadius() + slackMetres;
        for (int segment = 0; segment < hose->segmentCount(); ++segment) {
            const Vec3 a = hose->point(segment), b = hose->point(segment + 1);
            double t = 0.0, s = 0.0;
            if (raySegmentDistance2(ray, a, b, &t, &s) > radius * radius || t >= best)
                continue;
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
