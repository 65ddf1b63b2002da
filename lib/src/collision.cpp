// Collision with scene objects and clearance.
//
// The triangle hierarchy: median split on the longest centroid axis, ≤ 4 triangles per leaf,
// built iteratively (degenerate inputs cannot overflow a recursion), triangles stored in leaf
// order. Every query goes through MeshCollider::traverse (one traversal, a visitor per query)
// whose stack is sized from the depth recorded at build time. Queries run in the mesh's local
// frame; the Frame only transforms the query and the answer, so moving a collider costs nothing.
#include "chaintube/collision.h"

#include "chaintube/hose.h"
#include "projection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

namespace chaintube {

namespace {

constexpr int kLeafSize = 4;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Hose::applyCollisions: Newton steps of the chain projection with the contacts, and the
/// largest violation it stops at (relative length, radians, contact depth over a segment), from
/// which the span solver closes the rest exactly (Hose::closeSpans): its moves are of the order
/// of the violation.
constexpr int kContactProjectionSteps = 8;
constexpr double kContactProjectionClose = 1e-5;

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

// --- Hose: staying outside the colliders ----------------------------------------------------

} // namespace chaintube

#include "budget.h" // (the Hose half of this file alone uses it)

namespace chaintube {

void Hose::setColliders(std::vector<std::shared_ptr<const MeshCollider>> colliders,
                        const CollisionOptions& options)
{
    for (std::size_t i = 0; i < colliders.size(); ++i)
        if (!colliders[i])
            throw InvalidArgument("colliders[" + std::to_string(i) +
                                  "]: expected a collider, got null");
    if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance))
        throw InvalidArgument("collision tolerance: expected a finite value > 0 metres");
    if (!(options.constraintTolerance > 0.0) || !std::isfinite(options.constraintTolerance))
        throw InvalidArgument("collision constraintTolerance: expected a finite value > 0");
    if (options.maxRounds < 1) throw InvalidArgument("collision maxRounds: expected ≥ 1");
    m_colliders = std::move(colliders);
    m_collisionOptions = options;
    m_collisionStart.clear();
    m_collisionFree.clear();
    m_colliderFrames.clear();
    for (const auto& c : m_colliders)
        m_colliderFrames.push_back(c->frame());
    if (!m_colliders.empty()) m_collisionStart = m_local;
    m_collisionRevision = m_revision;
    m_edgePoint = -1; // grab(): what was the edge of reach may no longer be
}

UpdateResult Hose::resolveCollisions()
{
    BudgetScope scope(*this);
    UpdateResult result = measureViolation();
    result.status = Status::Ok;
    if (m_colliders.empty()) return result;
    if (m_collisionStart.size() != m_local.size()) m_collisionStart = m_local;
    applyCollisions(result, -1, Vec3::Zero());
    return result;
}

namespace {

bool sameFrame(const Frame& a, const Frame& b)
{
    return a.translation == b.translation && a.rotation.coeffs() == b.rotation.coeffs();
}

/// The colliders near one hose update, queried in world coordinates. A collider that moved
/// since the last update carries the relative motion new ∘ old⁻¹: a sweep that starts from the
/// hose's previous shape starts from where that shape sat relative to the collider, so a
/// moving collider pushes the hose instead of jumping over it.
class ContactSet
{
public:
    ContactSet(const std::vector<std::shared_ptr<const MeshCollider>>& all,
               const std::vector<Frame>& previousFrames, const Aabb& region)
    {
        for (std::size_t c = 0; c < all.size(); ++c) {
            const MeshCollider& collider = *all[c];
            Entry entry{&collider, Frame::identity(), false};
            if (c < previousFrames.size() && !sameFrame(previousFrames[c], collider.frame())) {
                entry.relative = collider.frame() * previousFrames[c].inverse();
                entry.moved = true;
            }
            // A collider that moved is always checked (its relative sweep starts elsewhere).
            if (entry.moved || boxBoxDistance2(collider.worldBounds(), region) == 0.0)
                m_near.push_back(entry);
        }
    }
    bool empty() const { return m_near.empty(); }

    struct Hit
    {
        MeshCollider::Sweep sweep;
        Vec3 start = Vec3::Zero(); ///< where the sweep began for the collider that was hit
    };
    /// First contact of a sphere moving from `from` to `to`; with relativeStart, `from` is a
    /// position of the previous update (see the class comment).
    Hit sweep(const Vec3& from, const Vec3& to, double radius, bool relativeStart) const
    {
        Hit best;
        for (const Entry& e : m_near) {
            const Vec3 start = relativeStart && e.moved ? e.relative.apply(from) : from;
            const MeshCollider::Sweep s = e.collider->sweepSphere(start, to, radius);
            if (s.hit && (!best.sweep.hit || s.fraction < best.sweep.fraction)) {
                best.sweep = s;
                best.start = start;
            }
        }
        return best;
    }
    MeshCollider::Closest closestToPoint(const Vec3& p, double maxDistance) const
    {
        MeshCollider::Closest best;
        for (const Entry& e : m_near) {
            const MeshCollider::Closest q =
                e.collider->closestToPoint(p, best.found ? best.distance : maxDistance);
            if (q.found && (!best.found || q.distance < best.distance)) best = q;
        }
        return best;
    }
    MeshCollider::Closest closestToSegment(const Vec3& a, const Vec3& b, double maxDistance) const
    {
        MeshCollider::Closest best;
        for (const Entry& e : m_near) {
            const MeshCollider::Closest q =
                e.collider->closestToSegment(a, b, best.found ? best.distance : maxDistance);
            if (q.found && (!best.found || q.distance < best.distance)) best = q;
        }
        return best;
    }

private:
    struct Entry
    {
        const MeshCollider* collider;
        Frame relative;
        bool moved;
    };
    std::vector<Entry> m_near;
};

} // namespace

void Hose::applyCollisions(UpdateResult& result, int grabbed, const Vec3& localTarget)
{
    if (m_colliders.empty()) return;
    const std::size_t n = m_local.size();
    const double radius = outerRadius();
    const double tolerance = m_collisionOptions.tolerance;
    // The previous shape is exactly the one before this update when only this update changed
    // the revision; a grab can then be redone from it (below).
    const bool startIsPrevious =
        m_collisionStart.size() == n && m_revision == m_collisionRevision + 1;
    if (m_collisionStart.size() != n) m_collisionStart = m_local;

    // Per-point lower bounds on the clearance (axis distance − radius) stay valid while no
    // collider moved; a point that moved less than its bound cannot have touched anything.
    bool collidersMoved =
        m_colliderFrames.size() != m_colliders.size() || m_collisionFree.size() != n;
    for (std::size_t c = 0; !collidersMoved && c < m_colliders.size(); ++c)
        collidersMoved = !sameFrame(m_colliderFrames[c], m_colliders[c]->frame());
    if (collidersMoved) m_collisionFree.assign(n, -kInf); // unknown: query before trusting
    auto finish = [&]() {
        m_collisionStart = m_local;
        m_colliderFrames.clear();
        for (const auto& c : m_colliders)
            m_colliderFrames.push_back(c->frame());
        m_collisionRevision = m_revision;
    };

    Aabb region;
    for (std::size_t i = 0; i < n; ++i) {
        region.extend(m_collisionStart[i] + m_origin);
        region.extend(m_local[i] + m_origin);
    }
    double maxRest = 0.0;
    for (double l : m_restLength)
        maxRest = std::max(maxRest, l);
    const double margin = radius + tolerance + maxRest;
    region.min.array() -= margin;
    region.max.array() += margin;
    const ContactSet contacts(m_colliders, m_colliderFrames, region);
    if (contacts.empty()) {
        m_collisionFree.assign(n, margin - radius); // no collider within margin of any point
        finish();
        return;
    }
    const double queryReach = radius + 2.0 * maxRest + 0.05; // bound on one clearance query

    std::vector<double>& freeBound = m_collisionFree;
    std::vector<unsigned char> pinned(m_fixed.begin(), m_fixed.end());
    if (grabbed >= 0) pinned[static_cast<std::size_t>(grabbed)] = 1;

    // Moves point i from `from` to `to` (local), stopping at first contact and sliding along
    // it (at most three contacts per move). Keeps freeBound[i] a lower bound.
    auto moveSwept = [&](std::size_t i, const Vec3& from, const Vec3& to, bool relativeStart) {
        const double length = (to - from).norm();
        if (freeBound[i] > length) {
            freeBound[i] -= length;
            return to;
        }
        Vec3 position = from + m_origin;
        const Vec3 goal = to + m_origin;
        bool touched = false;
        for (int slide = 0; slide < 3; ++slide) {
            if ((goal - position).norm() <= 1e-15 && !(relativeStart && slide == 0)) break;
            const ContactSet::Hit h =
                contacts.sweep(position, goal, radius, relativeStart && slide == 0);
            if (!h.sweep.hit) {
                position = goal;
                break;
            }
            touched = true;
            const Vec3 contact =
                h.start + h.sweep.fraction * (goal - h.start) + 1e-9 * h.sweep.normal;
            Vec3 rest = goal - contact;
            const double into = rest.dot(h.sweep.normal);
            if (into < 0.0) rest -= into * h.sweep.normal;
            position = contact;
            if (slide == 2) break;
            // Slide: the remaining move without its part into the surface.
            const Vec3 slideGoal = contact + rest;
            const ContactSet::Hit s2 = contacts.sweep(position, slideGoal, radius, false);
            if (!s2.sweep.hit) {
                position = slideGoal;
                break;
            }
            position =
                s2.start + s2.sweep.fraction * (slideGoal - s2.start) + 1e-9 * s2.sweep.normal;
            break;
        }
        freeBound[i] = touched ? 0.0 : freeBound[i] - length;
        return Vec3(position - m_origin);
    };

    std::vector<Vec3> solved = m_local; // where the collision-free solver put the points
    bool changed = false;

    // A grabbed point stopped by a collider: redo the grab from the previous shape towards
    // where the point can go, so the rest of the hose follows it with the exact ChainTube
    // propagation instead of being pushed into the obstacle after it.
    if (grabbed >= 0 && startIsPrevious) {
        const std::size_t k = static_cast<std::size_t>(grabbed);
        const Vec3 reach = moveSwept(k, m_collisionStart[k], solved[k], true);
        if ((reach - solved[k]).squaredNorm() > 1e-24) {
            std::vector<std::shared_ptr<const MeshCollider>> colliders;
            colliders.swap(m_colliders); // the redo itself must not recurse into collision
            m_local = m_collisionStart;
            const UpdateResult redo = grab(grabbed, reach + m_origin);
            m_colliders.swap(colliders);
            result.status = redo.status;
            result.lengthViolation = redo.lengthViolation;
            result.angleViolation = redo.angleViolation;
            result.movedPoints = redo.movedPoints;
            result.iterations += redo.iterations;
            solved = m_local;
            changed = true;
        }
        freeBound[k] = -kInf;
    }

    // Every point travels from its last collision-free place to where the solver put it;
    // fixed points are where their frames put them.
    m_local = m_collisionStart;
    for (std::size_t i = 0; i < n; ++i) {
        if (m_fixed[i]) {
            freeBound[i] -= (solved[i] - m_local[i]).norm();
            m_local[i] = solved[i];
            continue;
        }
        m_local[i] = moveSwept(i, m_local[i], solved[i], true);
        changed |= (m_local[i] - solved[i]).squaredNorm() > 1e-24;
    }

    // Exact clearance where the bound does not exclude contact.
    auto pointClearance = [&](std::size_t i, MeshCollider::Closest* closest) {
        if (freeBound[i] >= tolerance) return freeBound[i];
        const MeshCollider::Closest c = contacts.closestToPoint(m_local[i] + m_origin, queryReach);
        freeBound[i] = c.found ? c.distance - radius : queryReach - radius;
        if (closest) *closest = c;
        return freeBound[i];
    };
    // Pushes penetrating points and segments out (with `move`; otherwise only measures);
    // returns the deepest penetration found.
    auto pushOut = [&](bool move = true) {
        double deepest = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            MeshCollider::Closest c;
            const double free = pointClearance(i, &c);
            if (free >= -tolerance || !c.found) continue;
            deepest = std::max(deepest, -free);
            if (pinned[i] || !move) continue;
            Vec3 normal = c.normal;
            if (c.distance < 1e-12) { // centre on the surface: go back to the side it came from
                const Vec3 back = m_collisionStart[i] + m_origin - c.onMesh;
                if (back.dot(normal) < 0.0) normal = -normal;
            }
            m_local[i] = moveSwept(i, m_local[i], m_local[i] + normal * (-free), false);
            changed = true;
        }
        for (std::size_t s = 0; s + 1 < n; ++s) {
            const double length = (m_local[s + 1] - m_local[s]).norm();
            if (std::min(freeBound[s], freeBound[s + 1]) >= 0.5 * length + tolerance) continue;
            const MeshCollider::Closest c = contacts.closestToSegment(
                m_local[s] + m_origin, m_local[s + 1] + m_origin, radius - tolerance);
            if (!c.found || c.distance >= radius - tolerance) continue;
            const double depth = radius - c.distance;
            deepest = std::max(deepest, depth);
            if (!move) continue;
            Vec3 normal = c.normal;
            if (c.distance < 1e-12) {
                const Vec3 mid = 0.5 * (m_collisionStart[s] + m_collisionStart[s + 1]) + m_origin;
                if ((mid - c.onMesh).dot(normal) < 0.0) normal = -normal;
            }
            const double t = c.segmentParameter;
            const double wa = pinned[s] ? 0.0 : 1.0 - t, wb = pinned[s + 1] ? 0.0 : t;
            const double norm = wa * wa + wb * wb;
            if (!(norm > 1e-6)) continue;
            if (wa > 0.0)
                m_local[s] =
                    moveSwept(s, m_local[s], m_local[s] + normal * (depth * wa / norm), false);
            if (wb > 0.0)
                m_local[s + 1] = moveSwept(s + 1, m_local[s + 1],
                                           m_local[s + 1] + normal * (depth * wb / norm), false);
            changed = true;
        }
        return deepest;
    };

    // Places point i against its neighbour j = i ∓ 1: within the length band of their segment
    // and within the deflection limit at j (turn from the segment before j). Swept.
    auto project = [&](std::size_t i, std::size_t j) {
        const std::size_t segment = std::min(i, j);
        const Vec3 d = m_local[i] - m_local[j];
        double length = d.norm();
        Vec3 direction = Vec3::UnitX();
        if (length > 1e-12 * m_restLength[segment]) {
            direction = d / length;
        } else { // on top of each other: towards i's other neighbour, else the previous shape
            const long k = static_cast<long>(i) + (static_cast<long>(i) - static_cast<long>(j));
            Vec3 fallback = m_collisionStart[i] - m_collisionStart[j];
            if (k >= 0 && k < static_cast<long>(n))
                fallback = m_local[static_cast<std::size_t>(k)] - m_local[j];
            if (fallback.norm() > 0.0) direction = fallback.normalized();
        }
        const long g = static_cast<long>(j) + (static_cast<long>(j) - static_cast<long>(i));
        if (g >= 0 && g < static_cast<long>(n) && m_cosLimit[j] > -1.0 + 1e-12) {
            Vec3 u = m_local[j] - m_local[static_cast<std::size_t>(g)];
            const double uLength = u.norm();
            if (uLength > 1e-300) {
                u /= uLength;
                const double c = direction.dot(u);
                if (c < m_cosLimit[j]) {
                    Vec3 w = direction - c * u;
                    if (w.norm() < 1e-12) w = u.unitOrthogonal();
                    direction = m_cosLimit[j] * u + m_sinLimit[j] * w.normalized();
                }
            }
        }
        length = std::clamp(length, m_minLength[segment], m_maxLength[segment]);
        const Vec3 target = m_local[j] + length * direction;
        if ((target - m_local[i]).squaredNorm() > 1e-26) {
            m_local[i] = moveSwept(i, m_local[i], target, false);
            changed = true;
        }
    };

    double penetration = pushOut();
    const double ctol = m_collisionOptions.constraintTolerance;
    UpdateResult violation = changed ? measureViolation() : UpdateResult();
    bool fixedMoved = false;
    for (std::size_t i = 0; i < n && !fixedMoved; ++i)
        fixedMoved = m_fixed[i] && m_local[i] != m_collisionStart[i];
    // The contacts as rows of the chain projection (the tangent plane at the closest point of
    // each collider near a free point, which the axis keeps the outer radius and a tenth of the
    // tolerance above) with every length and bend: at most kContactProjectionSteps Newton steps
    // from the pushed-out shape, the rest closed by the span solver when they end near. The
    // result is kept when the points get there swept without touching anything and nothing
    // penetrates; otherwise the contact rounds below go on from the swept shape. When the steps
    // end far off, the update is refused (below) unless a fixed point moved: then only the
    // rounds are left.
    bool projectionFailed = false;
    if (changed && (violation.status != Status::Ok || penetration > tolerance)) {
        const std::vector<Vec3> before = m_local;
        detail::ChainProjection projection(*this);
        projection.setRange(0, static_cast<int>(n) - 1);
        projection.useMassesFromRestLengths(grabbed);
        const double reach = radius + tolerance + maxRest;
        for (std::size_t i = 0; i < n; ++i) {
            if (pinned[i]) continue;
            const MeshCollider::Closest c = contacts.closestToPoint(m_local[i] + m_origin, reach);
            if (c.found)
                static_cast<void>(projection.setContact(static_cast<int>(i), c, m_origin,
                                                        m_collisionStart[i],
                                                        radius + 0.1 * tolerance, 1e-12));
        }
        const detail::ProjectionOutcome out =
            projection.run(kContactProjectionSteps, kContactProjectionClose);
        result.iterations += out.iterations;
        if (out.converged && (measureViolation().status == Status::Ok ||
                              closeSpans(grabbed, before, result.iterations))) {
            const std::vector<Vec3> after = m_local;
            m_local = before;
            for (std::size_t i = 0; i < n; ++i)
                if (!pinned[i] && after[i] != before[i])
                    m_local[i] = moveSwept(i, before[i], after[i], false);
            penetration = pushOut(false);
            violation = measureViolation();
        } else {
            m_local = before;
            projectionFailed = true;
        }
    }
    const bool runRounds = !projectionFailed || fixedMoved;
    for (int round = 0; changed && runRounds && round < m_collisionOptions.maxRounds; ++round) {
        if (violation.lengthViolation <= ctol && violation.angleViolation <= ctol &&
            penetration <= tolerance)
            break;
        for (std::size_t i = 1; i < n; ++i)
            if (!pinned[i]) project(i, i - 1);
        for (std::size_t i = n - 1; i-- > 0;)
            if (!pinned[i]) project(i, i + 1);
        penetration = pushOut();
        violation = measureViolation();
    }
    // Lengths are never given up to contacts: when the rounds leave a segment outside its band,
    // or the projection found no shape, and no fixed point moved (a grab, a gravity step), the
    // hose stays at its last collision-resolved shape (if that one keeps its lengths) and the
    // update is reported blocked. (Fixed points stay where their frames put them.)
    bool refused = false;
    if (changed && !fixedMoved && (violation.lengthViolation > ctol || !runRounds)) {
        const std::vector<Vec3> rounds = m_local;
        m_local = m_collisionStart;
        const UpdateResult kept = measureViolation();
        if (kept.lengthViolation <= ctol) {
            refused = true;
            violation = kept;
            penetration = 0.0;
            for (std::size_t i = 0; i < n; ++i) {
                const MeshCollider::Closest c =
                    contacts.closestToPoint(m_local[i] + m_origin, queryReach);
                if (c.found) penetration = std::max(penetration, radius - c.distance);
                freeBound[i] = c.found ? c.distance - radius : queryReach - radius;
            }
            if (m_gravityPrevious.size() == n) m_gravityPrevious = m_local;
        } else {
            m_local = rounds;
        }
    }

    // Report.
    int touching = 0;
    for (std::size_t i = 0; i < n; ++i)
        if (pointClearance(i, nullptr) < 2.0 * tolerance) ++touching;
    result.contacts = touching;
    result.penetration = penetration > tolerance ? penetration : 0.0;
    bool blocked = result.penetration > 0.0 || refused;
    if (grabbed >= 0) {
        const std::size_t k = static_cast<std::size_t>(grabbed);
        if ((m_local[k] - localTarget).norm() > result.grabError + tolerance) {
            blocked = true;
            if (result.status == Status::Ok) result.status = Status::Clamped;
        }
        result.grabError = (m_local[k] - localTarget).norm();
    }
    result.blocked = blocked;
    // Refused and still inside a collider (one moved or flagged onto the hose): the contact is
    // not met, which the caller must not read as Ok.
    if (refused && result.penetration > 0.0 && result.status == Status::Ok)
        result.status = Status::Infeasible;
    if (changed) {
        result.lengthViolation = violation.lengthViolation;
        result.angleViolation = violation.angleViolation;
        m_dirtyViolation = violation.status != Status::Ok;
        if ((violation.lengthViolation > ctol || violation.angleViolation > ctol) &&
            result.status != Status::InvalidInput)
            result.status = Status::Infeasible;
        // Per-frame gravity (step()): a point a contact moved loses its velocity (the contact is
        // inelastic), or the Verlet step would turn the push-back into a bounce.
        if (m_gravityPrevious.size() == n)
            for (std::size_t i = 0; i < n; ++i)
                if (m_local[i] != solved[i]) m_gravityPrevious[i] = m_local[i];
        int moved = 0;
        for (std::size_t i = 0; i < n; ++i)
            moved += (m_local[i] - m_collisionStart[i]).squaredNorm() > 0.0;
        result.movedPoints = moved;
        ++m_revision;
    }
    finish();
}

} // namespace chaintube
