// Triangle-mesh colliders (MeshCollider) and the clearance of a hose from one.
//
// The triangle hierarchy: median split on the longest centroid axis, ≤ 4 triangles per leaf,
// built iteratively (degenerate inputs cannot overflow a recursion), triangles stored in leaf
// order. Every query goes through MeshCollider::traverse (one traversal, a visitor per query)
// whose stack is sized from the depth recorded at build time. Queries run in the mesh's local
// frame; the Frame only transforms the query and the answer, so moving a collider costs nothing.
#include "chaintube/collision.h"
#include "chaintube/hose.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

namespace chaintube {

namespace {

constexpr int kLeafSize = 4;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// sweepSegment(): a segment within this fraction of the guard distance beyond it is in contact
/// (conservative advancement converges on a contact only geometrically).
constexpr double kSegmentContactSlack = 0.02;

double boxDistance2(const Aabb& box, const Vec3& p)
{
    const Vec3 below = (box.min - p).cwiseMax(0.0);
    const Vec3 above = (p - box.max).cwiseMax(0.0);
    return below.squaredNorm() + above.squaredNorm();
}

/// Lower bound of the distance between two boxes (squared).
double boxBoxDistance2(const Aabb& a, const Aabb& b)
{
    const Vec3 gap = (a.min - b.max).cwiseMax(b.min - a.max).cwiseMax(0.0);
    return gap.squaredNorm();
}

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5).
Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c)
{
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0) return a;
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double denom = d1 - d3;
        return denom > 0.0 ? Vec3(a + (d1 / denom) * ab) : a;
    }
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double denom = d2 - d6;
        return denom > 0.0 ? Vec3(a + (d2 / denom) * ac) : a;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        const double denom = (d4 - d3) + (d5 - d6);
        return denom > 0.0 ? Vec3(b + ((d4 - d3) / denom) * (c - b)) : b;
    }
    const double sum = va + vb + vc;
    if (!(sum > 0.0)) return a; // degenerate triangle: handled by the edge cases above mostly
    return a + ab * (vb / sum) + ac * (vc / sum);
}

/// Closest points of segments p1q1 and p2q2 (Ericson 5.1.9); returns squared distance.
double closestSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2,
                             double* s, double* t, Vec3* c1, Vec3* c2)
{
    const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    constexpr double eps = 1e-300;
    if (a <= eps && e <= eps) {
        *s = *t = 0.0;
    } else if (a <= eps) {
        *s = 0.0;
        *t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = d1.dot(r);
        if (e <= eps) {
            *t = 0.0;
            *s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = d1.dot(d2), denom = a * e - b * b;
            *s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            *t = (b * *s + f) / e;
            if (*t < 0.0) {
                *t = 0.0;
                *s = std::clamp(-c / a, 0.0, 1.0);
            } else if (*t > 1.0) {
                *t = 1.0;
                *s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    *c1 = p1 + d1 * *s;
    *c2 = p2 + d2 * *t;
    return (*c1 - *c2).squaredNorm();
}

/// Closest points between segment pq and triangle abc; returns squared distance.
double closestSegmentTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                              const Vec3& c, double* s, Vec3* onSegment, Vec3* onTriangle)
{
    // A segment crossing the triangle: distance 0 at the crossing.
    const Vec3 n = (b - a).cross(c - a);
    const double dp = n.dot(p - a), dq = n.dot(q - a);
    if ((dp <= 0.0 && dq >= 0.0) || (dp >= 0.0 && dq <= 0.0)) {
        if (dp != dq) {
            const double t = dp / (dp - dq);
            const Vec3 x = p + t * (q - p);
            const Vec3 on = closestOnTriangle(x, a, b, c);
            if ((on - x).squaredNorm() <= 1e-24 * std::max(1.0, n.norm())) {
                *s = t;
                *onSegment = x;
                *onTriangle = on;
                return 0.0;
            }
        }
    }
    double best = kInf;
    auto consider = [&](double d2, double sv, const Vec3& os, const Vec3& ot) {
        if (d2 < best) {
            best = d2;
            *s = sv;
            *onSegment = os;
            *onTriangle = ot;
        }
    };
    const Vec3 cp = closestOnTriangle(p, a, b, c);
    consider((cp - p).squaredNorm(), 0.0, p, cp);
    const Vec3 cq = closestOnTriangle(q, a, b, c);
    consider((cq - q).squaredNorm(), 1.0, q, cq);
    const std::array<std::pair<Vec3, Vec3>, 3> edges{{{a, b}, {b, c}, {c, a}}};
    for (const auto& [e0, e1] : edges) {
        double sv = 0.0, tv = 0.0;
        Vec3 c1 = Vec3::Zero(), c2 = Vec3::Zero();
        const double d2 = closestSegmentSegment(p, q, e0, e1, &sv, &tv, &c1, &c2);
        consider(d2, sv, c1, c2);
    }
    return best;
}

/// Ray–triangle (Möller–Trumbore, two-sided); t in (0, maxT).
/// Slab test of the segment origin + t·(1 / inverse), t in [0, tmax], against `box` grown by
/// `pad`: whether it enters, and where (`entry`, the smallest t inside).
bool slabEntry(const Aabb& box, const Vec3& origin, const Vec3& inverse, double pad, double tmax,
               double& entry)
{
    double tmin = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
        double t0 = (box.min[axis] - pad - origin[axis]) * inverse[axis];
        double t1 = (box.max[axis] + pad - origin[axis]) * inverse[axis];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > tmin) tmin = t0; // NaN (0·inf) compares false: inside the slab
        if (t1 < tmax) tmax = t1;
        if (tmin > tmax) return false;
    }
    entry = tmin;
    return true;
}

bool rayTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c,
                 double maxT, double* t)
{
    const Vec3 e1 = b - a, e2 = c - a, pv = d.cross(e2);
    const double det = e1.dot(pv);
    if (std::abs(det) < 1e-300) return false;
    const double inv = 1.0 / det;
    const Vec3 tv = o - a;
    const double u = tv.dot(pv) * inv;
    if (u < 0.0 || u > 1.0) return false;
    const Vec3 qv = tv.cross(e1);
    const double v = d.dot(qv) * inv;
    if (v < 0.0 || u + v > 1.0) return false;
    const double hit = e2.dot(qv) * inv;
    if (!(hit > 0.0 && hit < maxT)) return false;
    *t = hit;
    return true;
}

/// Smallest root in [0, 1] of a t² + b t + c = 0 (c > 0: not touching at t = 0).
bool smallestRoot(double a, double b, double c, double* t)
{
    if (!(a > 0.0)) return false;
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return false;
    const double root = (-b - std::sqrt(disc)) / (2.0 * a);
    if (root < 0.0 || root > 1.0) return false;
    *t = root;
    return true;
}

/// First time in [0, 1] at which a sphere (centre p + t v, radius r) touches triangle abc, or
/// false. Overlap at t = 0 counts only when the sphere moves deeper (see MeshCollider::Sweep).
bool sweepSphereTriangle(const Vec3& p, const Vec3& v, double r, const Vec3& a, const Vec3& b,
                         const Vec3& c, double* tHit)
{
    const Vec3 c0 = closestOnTriangle(p, a, b, c);
    const double d0 = (p - c0).norm();
    const double speed = v.norm();
    // Touching at the start (to rounding) counts as overlap: only moving deeper is a contact.
    if (d0 <= r * (1.0 + 1e-12)) {
        Vec3 n = p - c0;
        if (d0 > 1e-12 * std::max(1.0, r))
            n /= d0;
        else {
            n = (b - a).cross(c - a);
            const double len = n.norm();
            if (!(len > 0.0)) return false;
            n /= len;
            if (n.dot(v) > 0.0) n = -n; // moving along the normal: deeper is −n either way
            return speed > 0.0;         // centre on the plane and moving: a crossing
        }
        if (n.dot(v) < -1e-12 * speed) {
            *tHit = 0.0;
            return true;
        }
        return false;
    }
    if (!(speed > 0.0)) return false;
    double best = kInf, t = 0.0;
    // Face: the sphere meets the plane with its contact point inside the triangle.
    Vec3 n = (b - a).cross(c - a);
    const double nLen = n.norm();
    if (nLen > 0.0) {
        n /= nLen;
        const double s0 = n.dot(p - a), sv = n.dot(v);
        if (std::abs(s0) >= r && s0 * sv < 0.0) {
            const double side = s0 > 0.0 ? 1.0 : -1.0;
            t = (side * r - s0) / sv;
            if (t >= 0.0 && t <= 1.0) {
                const Vec3 contact = p + t * v - side * r * n;
                const Vec3 onTri = closestOnTriangle(contact, a, b, c);
                if ((onTri - contact).squaredNorm() <= 1e-20 * std::max(1.0, r * r)) best = t;
            }
        }
    }
    // Vertices.
    for (const Vec3* vertex : {&a, &b, &c}) {
        const Vec3 w = p - *vertex;
        if (smallestRoot(v.squaredNorm(), 2.0 * v.dot(w), w.squaredNorm() - r * r, &t))
            best = std::min(best, t);
    }
    // Edges: the sphere meets the edge's cylinder at a parameter inside the edge.
    const std::array<std::pair<const Vec3*, const Vec3*>, 3> edges{{{&a, &b}, {&b, &c}, {&c, &a}}};
    for (const auto& [e0, e1] : edges) {
        const Vec3 edge = *e1 - *e0;
        const double e2 = edge.squaredNorm();
        if (!(e2 > 0.0)) continue;
        const Vec3 w = p - *e0;
        const Vec3 wPerp = w - (w.dot(edge) / e2) * edge, vPerp = v - (v.dot(edge) / e2) * edge;
        if (smallestRoot(vPerp.squaredNorm(), 2.0 * wPerp.dot(vPerp), wPerp.squaredNorm() - r * r,
                         &t)) {
            const double f = (w + t * v).dot(edge) / e2;
            if (f >= 0.0 && f <= 1.0) best = std::min(best, t);
        }
    }
    if (best > 1.0) return false;
    *tHit = best;
    return true;
}

} // namespace

// --- MeshCollider -----------------------------------------------------------------------------

std::shared_ptr<MeshCollider> MeshCollider::fromArrays(const float* positions,
                                                       std::size_t vertexCount,
                                                       const std::uint32_t* indices,
                                                       std::size_t indexCount, const Frame& frame)
{
    if (vertexCount == 0)
        throw InvalidArgument("collider positions: expected at least one vertex, got 0");
    if (positions == nullptr)
        throw InvalidArgument("collider positions: null pointer for " +
                              std::to_string(vertexCount) + " vertices");
    std::vector<Vec3> points(vertexCount);
    for (std::size_t i = 0; i < vertexCount; ++i)
        points[i] = Vec3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
    if (indexCount > 0 && indices == nullptr)
        throw InvalidArgument("collider indices: null pointer for " + std::to_string(indexCount) +
                              " indices");
    std::vector<std::uint32_t> list(indices, indices + indexCount);
    return fromArrays(points, list, frame);
}

std::shared_ptr<MeshCollider> MeshCollider::fromArrays(const std::vector<Vec3>& positions,
                                                       const std::vector<std::uint32_t>& indices,
                                                       const Frame& frame)
{
    if (positions.empty())
        throw InvalidArgument("collider positions: expected at least one vertex, got 0");
    if (indices.empty() || indices.size() % 3 != 0)
        throw InvalidArgument(
            "collider indices: expected a non-zero multiple of 3 (three per triangle), got " +
            std::to_string(indices.size()));
    for (std::size_t i = 0; i < positions.size(); ++i)
        if (!positions[i].allFinite())
            throw InvalidArgument("collider positions[" + std::to_string(i) +
                                  "]: expected finite coordinates");
    for (std::size_t i = 0; i < indices.size(); ++i)
        if (indices[i] >= positions.size())
            throw InvalidArgument("collider indices[" + std::to_string(i) +
                                  "] = " + std::to_string(indices[i]) +
                                  ": expected < vertex count " + std::to_string(positions.size()));
    if (!isFiniteFrame(frame))
        throw InvalidArgument("collider frame: expected a finite rigid frame");
    std::shared_ptr<MeshCollider> collider(new MeshCollider());
    collider->m_frame = frame;
    collider->m_triangles.reserve(indices.size() / 3);
    for (std::size_t t = 0; t < indices.size(); t += 3)
        collider->m_triangles.push_back(
            {positions[indices[t]], positions[indices[t + 1]], positions[indices[t + 2]]});
    collider->build();
    return collider;
}

void MeshCollider::build()
{
    const int count = static_cast<int>(m_triangles.size());
    std::vector<Vec3> centroids(m_triangles.size());
    for (std::size_t i = 0; i < m_triangles.size(); ++i)
        centroids[i] = (m_triangles[i].a + m_triangles[i].b + m_triangles[i].c) / 3.0;
    std::vector<int> order(m_triangles.size());
    std::iota(order.begin(), order.end(), 0);
    m_nodes.reserve(2 * m_triangles.size() / kLeafSize + 2);
    m_nodes.emplace_back();
    struct Task
    {
        int node, first, count, depth;
    };
    m_depth = 0;
    std::vector<Task> stack{{0, 0, count, 0}};
    while (!stack.empty()) {
        const Task task = stack.back();
        stack.pop_back();
        m_depth = std::max(m_depth, task.depth);
        Aabb box, centroidBox;
        for (int i = task.first; i < task.first + task.count; ++i) {
            const Triangle& tri =
                m_triangles[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
            box.extend(tri.a);
            box.extend(tri.b);
            box.extend(tri.c);
            centroidBox.extend(
                centroids[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])]);
        }
        m_nodes[static_cast<std::size_t>(task.node)].box = box;
        const Vec3 extent = centroidBox.max - centroidBox.min;
        int axis = 0;
        extent.maxCoeff(&axis);
        if (task.count <= kLeafSize) {
            m_nodes[static_cast<std::size_t>(task.node)].first = task.first;
            m_nodes[static_cast<std::size_t>(task.node)].count = task.count;
            continue;
        }
        // Always split in halves, so leaves stay small and the depth is ⌈log2(count / 4)⌉
        // whatever the input: triangles whose centroids coincide (many at one spot) are split
        // in the order given; their boxes then overlap, which costs time, never an answer.
        const int half = task.count / 2;
        auto begin = order.begin() + task.first;
        if (extent[axis] > 0.0)
            std::nth_element(begin, begin + half, begin + task.count, [&](int x, int y) {
                return centroids[static_cast<std::size_t>(x)][axis] <
                       centroids[static_cast<std::size_t>(y)][axis];
            });
        const int left = static_cast<int>(m_nodes.size());
        m_nodes.emplace_back();
        m_nodes.emplace_back();
        m_nodes[static_cast<std::size_t>(task.node)].first = left;
        m_nodes[static_cast<std::size_t>(task.node)].count = 0;
        stack.push_back({left, task.first, half, task.depth + 1});
        stack.push_back({left + 1, task.first + half, task.count - half, task.depth + 1});
    }
    // Store triangles in leaf order (locality); remember each one's index as given.
    std::vector<Triangle> sorted(m_triangles.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        sorted[i] = m_triangles[static_cast<std::size_t>(order[i])];
    m_triangles.swap(sorted);
    m_originalIndex = order;
    m_localBounds = m_nodes[0].box;
}

bool MeshCollider::setFrame(const Frame& frame)
{
    if (!isFiniteFrame(frame)) return false;
    m_frame = frame;
    ++m_revision;
    return true;
}

Aabb MeshCollider::worldBounds() const
{
    Aabb out;
    if (m_localBounds.empty()) return out;
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3 p((corner & 1) ? m_localBounds.max.x() : m_localBounds.min.x(),
                     (corner & 2) ? m_localBounds.max.y() : m_localBounds.min.y(),
                     (corner & 4) ? m_localBounds.max.z() : m_localBounds.min.z());
        out.extend(m_frame.apply(p));
    }
    return out;
}

/// The one traversal of the hierarchy behind every query: depth first, children in the order
/// the visitor prefers. The visitor supplies
///   bool enter(const Aabb& box, double& key)  — false: nothing in this box can matter; key: a
///                                               lower bound of what the box can give (smaller
///                                               keys are visited first);
///   bool worth(double key) const              — re-checked when a node is popped (the best
///                                               answer may have improved since it was pushed);
///   void leaf(int first, int count)           — the triangles first … first + count − 1.
/// The stack holds at most depth + 1 entries (each inner node pops itself and pushes two), and
/// build() records the depth, so no subtree is ever skipped: a small array up to depth 62, a
/// heap buffer beyond (not reachable with the median split below 2^60 triangles, but correct).
template <class Visitor> void MeshCollider::traverse(Visitor& visitor) const
{
    if (m_nodes.empty()) return;
    struct Entry
    {
        int node;
        double key;
    };
    constexpr int kInline = 64;
    std::array<Entry, kInline> inlineStack;
    std::vector<Entry> heapStack;
    Entry* stack = inlineStack.data();
    if (m_depth + 2 > kInline) {
        heapStack.resize(static_cast<std::size_t>(m_depth) + 2);
        stack = heapStack.data();
    }
    int top = 0;
    double rootKey = 0.0;
    if (!visitor.enter(m_nodes[0].box, rootKey)) return;
    stack[top++] = {0, rootKey};
    while (top > 0) {
        const Entry entry = stack[--top];
        if (!visitor.worth(entry.key)) continue;
        const Node& node = m_nodes[static_cast<std::size_t>(entry.node)];
        if (node.count > 0) {
            visitor.leaf(node.first, node.count);
            continue;
        }
        const int left = node.first, right = node.first + 1;
        double leftKey = 0.0, rightKey = 0.0;
        const bool enterLeft = visitor.enter(m_nodes[static_cast<std::size_t>(left)].box, leftKey);
        const bool enterRight =
            visitor.enter(m_nodes[static_cast<std::size_t>(right)].box, rightKey);
        // The preferred child is pushed last, so it is popped first.
        if (enterLeft && enterRight && leftKey < rightKey) {
            stack[top++] = {right, rightKey};
            stack[top++] = {left, leftKey};
        } else {
            if (enterLeft) stack[top++] = {left, leftKey};
            if (enterRight) stack[top++] = {right, rightKey};
        }
    }
}

MeshCollider::Closest MeshCollider::closestToPoint(const Vec3& point, double maxDistance) const
{
    Closest result;
    if (!point.allFinite() || m_nodes.empty() || !(maxDistance >= 0.0)) return result;
    struct Visitor
    {
        const MeshCollider& mesh;
        Vec3 p;
        double best2;
        int bestTriangle = -1;
        Vec3 bestPoint = Vec3::Zero();
        bool enter(const Aabb& box, double& key) const
        {
            key = boxDistance2(box, p);
            return key <= best2;
        }
        bool worth(double key) const { return key <= best2; }
        void leaf(int first, int count)
        {
            for (int i = first; i < first + count; ++i) {
                const Triangle& tri = mesh.m_triangles[static_cast<std::size_t>(i)];
                const Vec3 on = closestOnTriangle(p, tri.a, tri.b, tri.c);
                const double d2 = (on - p).squaredNorm();
                if (d2 <= best2) {
                    best2 = d2;
                    bestTriangle = i;
                    bestPoint = on;
                }
            }
        }
    } visitor{*this, m_frame.applyInverse(point),
              maxDistance == kInf ? kInf : maxDistance * maxDistance};
    traverse(visitor);
    if (visitor.bestTriangle < 0) return result;
    const Vec3& p = visitor.p;
    const Triangle& tri = m_triangles[static_cast<std::size_t>(visitor.bestTriangle)];
    result.found = true;
    result.distance = std::sqrt(visitor.best2);
    result.onMesh = m_frame.apply(visitor.bestPoint);
    result.onQuery = point;
    result.triangle = m_originalIndex[static_cast<std::size_t>(visitor.bestTriangle)];
    Vec3 n = p - visitor.bestPoint;
    if (!(n.norm() > 1e-15)) n = (tri.b - tri.a).cross(tri.c - tri.a);
    if (n.norm() > 0.0) result.normal = m_frame.rotation * n.normalized();
    return result;
}

MeshCollider::Closest MeshCollider::closestToSegment(const Vec3& a, const Vec3& b,
                                                     double maxDistance) const
{
    Closest result;
    if (!a.allFinite() || !b.allFinite() || m_nodes.empty() || !(maxDistance >= 0.0)) return result;
    struct Visitor
    {
        const MeshCollider& mesh;
        Vec3 p, q;
        Aabb segmentBox;
        double best2;
        int bestTriangle = -1;
        Vec3 bestOnSegment = Vec3::Zero(), bestOnMesh = Vec3::Zero();
        double bestS = 0.0;
        bool enter(const Aabb& box, double& key) const
        {
            key = boxBoxDistance2(box, segmentBox);
            return key <= best2;
        }
        bool worth(double key) const { return key <= best2; }
        void leaf(int first, int count)
        {
            for (int i = first; i < first + count; ++i) {
                const Triangle& tri = mesh.m_triangles[static_cast<std::size_t>(i)];
                // Cheap rejection: the segment on one side of the triangle's plane, farther
                // from it than the best so far, cannot be closer to the triangle.
                const Vec3 n = (tri.b - tri.a).cross(tri.c - tri.a);
                const double n2 = n.squaredNorm();
                if (n2 > 0.0) {
                    const double dp = n.dot(p - tri.a), dq = n.dot(q - tri.a);
                    const double nearest = std::min(std::abs(dp), std::abs(dq));
                    if (dp * dq > 0.0 && nearest * nearest > best2 * n2) continue;
                }
                double s = 0.0;
                Vec3 onSegment = Vec3::Zero(), onTriangle = Vec3::Zero();
                const double d2 =
                    closestSegmentTriangle(p, q, tri.a, tri.b, tri.c, &s, &onSegment, &onTriangle);
                if (d2 <= best2) {
                    best2 = d2;
                    bestTriangle = i;
                    bestS = s;
                    bestOnSegment = onSegment;
                    bestOnMesh = onTriangle;
                }
            }
        }
    } visitor{*this, m_frame.applyInverse(a), m_frame.applyInverse(b), Aabb(),
              maxDistance == kInf ? kInf : maxDistance * maxDistance};
    visitor.segmentBox.extend(visitor.p);
    visitor.segmentBox.extend(visitor.q);
    traverse(visitor);
    if (visitor.bestTriangle < 0) return result;
    const Triangle& tri = m_triangles[static_cast<std::size_t>(visitor.bestTriangle)];
    result.found = true;
    result.distance = std::sqrt(visitor.best2);
    result.onMesh = m_frame.apply(visitor.bestOnMesh);
    result.onQuery = m_frame.apply(visitor.bestOnSegment);
    result.segmentParameter = visitor.bestS;
    result.triangle = m_originalIndex[static_cast<std::size_t>(visitor.bestTriangle)];
    Vec3 n = visitor.bestOnSegment - visitor.bestOnMesh;
    if (!(n.norm() > 1e-15)) n = (tri.b - tri.a).cross(tri.c - tri.a);
    if (n.norm() > 0.0) result.normal = m_frame.rotation * n.normalized();
    return result;
}

MeshCollider::Sweep MeshCollider::sweepSphere(const Vec3& from, const Vec3& to, double radius) const
{
    Sweep result;
    if (!from.allFinite() || !to.allFinite() || !(radius >= 0.0) || m_nodes.empty()) return result;
    struct Visitor
    {
        const MeshCollider& mesh;
        Vec3 p, q, v, inverse;
        double radius;
        Aabb swept;
        double best = kInf;
        int bestTriangle = -1;
        // The sphere can touch a box's triangles only inside the box grown by the radius: key
        // is when the centre's path enters that box (slab test), so nearer boxes are searched
        // first and boxes entered after the first contact found are skipped. Long sweeps that
        // hit (a 1.5 m move across a 1M-triangle height field) tested up to 170,000 triangles
        // with the swept-box overlap alone.
        bool enter(const Aabb& box, double& key) const
        {
            if (boxBoxDistance2(box, swept) > 0.0) return false;
            return slabEntry(box, p, inverse, radius, std::min(1.0, best), key);
        }
        bool worth(double key) const { return key <= best; }
        void leaf(int first, int count)
        {
            for (int i = first; i < first + count; ++i) {
                const Triangle& tri = mesh.m_triangles[static_cast<std::size_t>(i)];
                // Cheap rejection: start and end on one side of the plane, both at least the
                // radius from it (touching counts only when moving deeper, which this is not).
                const Vec3 n = (tri.b - tri.a).cross(tri.c - tri.a);
                const double n2 = n.squaredNorm();
                if (n2 > 0.0) {
                    const double dp = n.dot(p - tri.a), dq = n.dot(q - tri.a);
                    const double nearest = std::min(std::abs(dp), std::abs(dq));
                    const double reach = radius * (1.0 - 1e-9);
                    if (dp * dq > 0.0 && nearest * nearest >= reach * reach * n2) continue;
                }
                double t = 0.0;
                if (sweepSphereTriangle(p, v, radius, tri.a, tri.b, tri.c, &t) && t < best) {
                    best = t;
                    bestTriangle = i;
                }
            }
        }
    } visitor{*this,
              m_frame.applyInverse(from),
              m_frame.applyInverse(to),
              Vec3::Zero(),
              Vec3::Zero(),
              radius,
              Aabb()};
    visitor.v = visitor.q - visitor.p;
    visitor.inverse = Vec3(1.0 / visitor.v.x(), 1.0 / visitor.v.y(), 1.0 / visitor.v.z());
    visitor.swept.extend(visitor.p);
    visitor.swept.extend(visitor.q);
    visitor.swept.min.array() -= radius;
    visitor.swept.max.array() += radius;
    traverse(visitor);
    if (visitor.bestTriangle < 0) return result;
    const Triangle& tri = m_triangles[static_cast<std::size_t>(visitor.bestTriangle)];
    result.hit = true;
    result.fraction = visitor.best;
    result.triangle = m_originalIndex[static_cast<std::size_t>(visitor.bestTriangle)];
    const Vec3 centre = visitor.p + visitor.best * visitor.v;
    Vec3 n = centre - closestOnTriangle(centre, tri.a, tri.b, tri.c);
    if (!(n.norm() > 1e-15 * std::max(1.0, radius))) {
        n = (tri.b - tri.a).cross(tri.c - tri.a);
        if (n.dot(visitor.v) > 0.0) n = -n;
    }
    if (n.norm() > 0.0) result.normal = m_frame.rotation * n.normalized();
    return result;
}

MeshCollider::SegmentSweep MeshCollider::sweepSegment(const Vec3& a0, const Vec3& b0,
                                                      const Vec3& a1, const Vec3& b1, double radius,
                                                      int maxQueries) const
{
    SegmentSweep result;
    if (!a0.allFinite() || !b0.allFinite() || !a1.allFinite() || !b1.allFinite() ||
        !(radius >= 0.0) || m_nodes.empty())
        return result;
    // Every point of the segment moves at most as far as its farther-moving end (the points
    // are affine combinations of the ends with the same weights throughout the move).
    const double travel = std::max((a1 - a0).norm(), (b1 - b0).norm());
    double guard = radius;
    double t = 0.0;
    for (int query = 0; query < std::max(1, maxQueries); ++query) {
        const Vec3 a = a0 + t * (a1 - a0), b = b0 + t * (b1 - b0);
        const Closest c = closestToSegment(a, b, guard + travel * (1.0 - t));
        ++result.queries;
        if (!c.found) return result; // nothing within reach of the rest of the move
        // At the start within the guard, or within the slack beyond it (a segment an earlier
        // sweep stopped there): keep half the starting distance, so it can move off or along.
        if (query == 0 && c.distance < guard * (1.0 + 2.0 * kSegmentContactSlack)) {
            if (!(c.distance > 0.0)) return result; // crossing already: nothing left to keep
            guard = 0.5 * c.distance;
        }
        const double gap = c.distance - guard;
        if (!(travel > 0.0)) return result; // not moving: cannot get nearer
        if (gap <= kSegmentContactSlack * guard) {
            result.hit = true;
            result.fraction = t;
            result.normal = c.normal;
            return result;
        }
        result.normal = c.normal;
        t += gap / travel;
        if (t >= 1.0) {
            result.normal = Vec3::UnitY();
            return result;
        }
    }
    result.hit = true;
    result.bounded = true;
    result.fraction = t;
    return result;
}

MeshCollider::RayHit MeshCollider::raycast(const Vec3& origin, const Vec3& direction,
                                           double maxT) const
{
    RayHit result;
    if (!origin.allFinite() || !direction.allFinite() || !(direction.norm() > 0.0) ||
        m_nodes.empty())
        return result;
    struct Visitor
    {
        const MeshCollider& mesh;
        Vec3 o, d, inverse;
        double best;
        int bestTriangle = -1;
        int tested = 0;
        bool enter(const Aabb& box, double& key) const
        {
            return slabEntry(box, o, inverse, 0.0, best, key);
        }
        bool worth(double key) const { return key <= best; }
        void leaf(int first, int count)
        {
            tested += count;
            for (int i = first; i < first + count; ++i) {
                const Triangle& tri = mesh.m_triangles[static_cast<std::size_t>(i)];
                double t = 0.0;
                if (rayTriangle(o, d, tri.a, tri.b, tri.c, best, &t)) {
                    best = t;
                    bestTriangle = i;
                }
            }
        }
    } visitor{*this, m_frame.applyInverse(origin), m_frame.rotation.conjugate() * direction,
              Vec3::Zero(), maxT};
    visitor.inverse = Vec3(1.0 / visitor.d.x(), 1.0 / visitor.d.y(), 1.0 / visitor.d.z());
    traverse(visitor);
    result.trianglesTested = visitor.tested;
    if (visitor.bestTriangle < 0) return result;
    const Triangle& tri = m_triangles[static_cast<std::size_t>(visitor.bestTriangle)];
    result.hit = true;
    result.t = visitor.best;
    result.triangle = m_originalIndex[static_cast<std::size_t>(visitor.bestTriangle)];
    Vec3 n = (tri.b - tri.a).cross(tri.c - tri.a);
    if (n.dot(visitor.d) > 0.0) n = -n;
    if (n.norm() > 0.0) result.normal = m_frame.rotation * n.normalized();
    return result;
}

// --- clearance ----------------------------------------------------------------------------

Clearance clearance(const Hose& hose, const MeshCollider& collider, double searchDistance)
{
    Clearance result;
    const double radius = hose.outerRadius();
    double best = searchDistance == kInf ? kInf : std::max(0.0, searchDistance + radius);
    for (int s = 0; s < hose.segmentCount(); ++s) {
        const Vec3 a = hose.point(s), b = hose.point(s + 1);
        const MeshCollider::Closest c = collider.closestToSegment(a, b, best);
        if (!c.found || (result.found && c.distance >= best)) continue;
        best = c.distance;
        result.found = true;
        result.distance = c.distance - radius;
        result.segment = s;
        result.axisPoint = c.segmentParameter <= 0.5 ? s : s + 1;
        result.onAxis = c.onQuery;
        result.onObject = c.onMesh;
        result.onSurface = c.onQuery - radius * c.normal;
        result.triangle = c.triangle;
    }
    return result;
}

} // namespace chaintube
