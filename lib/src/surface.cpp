#include "chaintube/surface.h"

#include <cmath>

namespace chaintube {

namespace {
Vec3 perpendicularPart(const Vec3& v, const Vec3& unitAxis) { return v - v.dot(unitAxis) * unitAxis; }

Vec3 defaultAlignment(const Vec3& tangent)
{
    Vec3 a = perpendicularPart(Vec3::UnitY(), tangent);
    if (a.norm() < 1e-6) a = perpendicularPart(Vec3::UnitX(), tangent);
    return a.normalized();
}
} // namespace

Quat RingFrame::rotation() const
{
    Mat3 m;
    m.col(0) = alignment;
    m.col(1) = binormal;
    m.col(2) = tangent;
    return Quat(m).normalized();
}

void computeRingFrames(const Hose& hose, TwistSeed& seed, std::vector<RingFrame>& frames)
{
    const std::vector<Vec3>& p = hose.localPoints();
    const size_t n = p.size();
    frames.resize(n);
    for (size_t i = 0; i < n; ++i) frames[i].center = p[i];

    // Ring plane normals.
    Vec3 previousDirection = (p[1] - p[0]).normalized();
    frames[0].tangent = previousDirection;
    for (size_t i = 1; i < n; ++i) {
        if (i + 1 == n) {
            frames[i].tangent = previousDirection;
            break;
        }
        const Vec3 direction = (p[i + 1] - p[i]).normalized();
        Vec3 bisector = previousDirection + direction;
        if (bisector.norm() > 1e-9) {
            frames[i].tangent = bisector.normalized();
        } else {
            Vec3 t = perpendicularPart(frames[i - 1].tangent, direction);
            if (t.norm() < 1e-9) t = perpendicularPart(Vec3::UnitY(), direction);
            if (t.norm() < 1e-9) t = perpendicularPart(Vec3::UnitX(), direction);
            frames[i].tangent = t.normalized();
        }
        previousDirection = direction;
    }

    // First alignment: carried over from the previous frame.
    const Vec3& t0 = frames[0].tangent;
    Vec3 a0;
    if (seed.alignment.squaredNorm() == 0.0) {
        a0 = defaultAlignment(t0);
    } else {
        const double c = seed.tangent.dot(t0);
        Vec3 carried = seed.alignment;
        if (c > -1.0 + 1e-9) {
            const Vec3 k = seed.tangent.cross(t0);
            carried = seed.alignment * c + k.cross(seed.alignment) + k * (k.dot(seed.alignment) / (1.0 + c));
        }
        a0 = perpendicularPart(carried, t0);
        a0 = a0.norm() > 1e-9 ? Vec3(a0.normalized()) : defaultAlignment(t0);
    }
    frames[0].alignment = a0;
    frames[0].binormal = t0.cross(a0);
    seed.tangent = t0;
    seed.alignment = a0;

    // Rotation-minimising transport along the axis (double reflection).
    for (size_t i = 1; i < n; ++i) {
        const RingFrame& before = frames[i - 1];
        RingFrame& ring = frames[i];
        const Vec3 v1 = ring.center - before.center;
        const double b1 = v1.squaredNorm();
        Vec3 alignment = before.alignment;
        Vec3 tangentL = before.tangent;
        if (b1 > 0.0) {
            alignment -= (2.0 / b1) * v1.dot(alignment) * v1;
            tangentL -= (2.0 / b1) * v1.dot(tangentL) * v1;
        }
        const Vec3 v2 = ring.tangent - tangentL;
        const double b2 = v2.squaredNorm();
        if (b2 > 1e-30) alignment -= (2.0 / b2) * v2.dot(alignment) * v2;
        alignment = perpendicularPart(alignment, ring.tangent);
        const double length = alignment.norm();
        ring.alignment = length > 1e-9 ? Vec3(alignment / length)
                                        : defaultAlignment(ring.tangent);
        ring.binormal = ring.tangent.cross(ring.alignment);
    }
}

SurfaceTopology SurfaceTopology::build(const Hose& hose)
{
    const Profile& profile = hose.profile();
    SurfaceTopology t;
    t.ringCount = hose.pointCount();
    t.ringVertexCount = profile.vertexCount();
    t.capVertexCount = static_cast<int>(profile.corners().size());
    t.vertexCount = t.ringCount * t.ringVertexCount + 2 * t.capVertexCount;
    const auto rv = static_cast<std::uint32_t>(t.ringVertexCount);
    for (std::uint32_t i = 0; i + 1 < static_cast<std::uint32_t>(t.ringCount); ++i)
        for (std::uint32_t j = 0; j + 1 < rv; ++j) {
            if (!profile.isFaceEdge(static_cast<int>(j))) continue;
            const std::uint32_t a = i * rv + j, b = a + 1, c = (i + 1) * rv + j + 1, d = (i + 1) * rv + j;
            t.indices.insert(t.indices.end(), {a, b, c, a, c, d});
        }
    const auto startCap = static_cast<std::uint32_t>(t.ringCount) * rv;
    const auto endCap = startCap + static_cast<std::uint32_t>(t.capVertexCount);
    const std::vector<int>& cap = profile.capTriangles();
    for (size_t k = 0; k + 2 < cap.size(); k += 3) {
        const auto c0 = static_cast<std::uint32_t>(cap[k]), c1 = static_cast<std::uint32_t>(cap[k + 1]),
                   c2 = static_cast<std::uint32_t>(cap[k + 2]);
        t.indices.insert(t.indices.end(), {startCap + c0, startCap + c2, startCap + c1});
        t.indices.insert(t.indices.end(), {endCap + c0, endCap + c1, endCap + c2});
    }

    t.uvs.resize(2 * static_cast<size_t>(t.vertexCount));
    t.vertexRing.resize(static_cast<size_t>(t.vertexCount));
    double along = 0.0;
    for (int i = 0; i < t.ringCount; ++i) {
        if (i > 0) along += hose.restLength(i - 1);
        for (int j = 0; j < t.ringVertexCount; ++j) {
            const size_t v = static_cast<size_t>(i * t.ringVertexCount + j);
            t.uvs[2 * v] = static_cast<float>(profile.u()[static_cast<size_t>(j)]);
            t.uvs[2 * v + 1] = static_cast<float>(along);
            t.vertexRing[v] = static_cast<std::uint32_t>(i);
        }
    }
    const double extent = std::max(profile.boundingRadius(), 1e-300);
    for (int side = 0; side < 2; ++side)
        for (int c = 0; c < t.capVertexCount; ++c) {
            const size_t v = (side == 0 ? startCap : endCap) + static_cast<size_t>(c);
            const Vec2& corner = profile.corners()[static_cast<size_t>(c)];
            t.uvs[2 * v] = static_cast<float>(0.5 + 0.5 * corner.x() / extent);
            t.uvs[2 * v + 1] = static_cast<float>(0.5 + 0.5 * corner.y() / extent);
            t.vertexRing[v] = side == 0 ? 0u : static_cast<std::uint32_t>(t.ringCount - 1);
        }
    return t;
}

HoseSurface::HoseSurface(const Hose& hose) { update(hose); }

void HoseSurface::rebuildTopology(const Hose& hose)
{
    m_topology = SurfaceTopology::build(hose);
    m_profile = hose.profile();
    m_pointCount = hose.pointCount();
    const Profile& profile = hose.profile();
    m_profilePoints.clear();
    m_profileNormals.clear();
    for (int j = 0; j < profile.vertexCount(); ++j) {
        m_profilePoints.push_back(static_cast<float>(profile.points()[static_cast<size_t>(j)].x()));
        m_profilePoints.push_back(static_cast<float>(profile.points()[static_cast<size_t>(j)].y()));
        m_profileNormals.push_back(static_cast<float>(profile.normals()[static_cast<size_t>(j)].x()));
        m_profileNormals.push_back(static_cast<float>(profile.normals()[static_cast<size_t>(j)].y()));
    }
    m_positions.assign(3 * static_cast<size_t>(m_topology.vertexCount), 0.0f);
    m_normals.assign(3 * static_cast<size_t>(m_topology.vertexCount), 0.0f);
}

bool HoseSurface::update(const Hose& hose)
{
    if (m_seenRevision == hose.revision() && m_pointCount == hose.pointCount()) return false;
    if (m_pointCount != hose.pointCount() || !(m_profile == hose.profile()) ||
        m_profile.vertexCount() != hose.profile().vertexCount())
        rebuildTopology(hose);
    computeRingFrames(hose, m_seed, m_frames);
    writeVertices(hose);
    m_seenRevision = hose.revision();
    return true;
}

void HoseSurface::writeVertices(const Hose& hose)
{
    const int rv = m_topology.ringVertexCount;
    const float* px = m_profilePoints.data();
    const float* nx = m_profileNormals.data();
    float* pos = m_positions.data();
    float* nrm = m_normals.data();
    for (const RingFrame& ring : m_frames) {
        const float cx = static_cast<float>(ring.center.x()), cy = static_cast<float>(ring.center.y()),
                    cz = static_cast<float>(ring.center.z());
        const float ax = static_cast<float>(ring.alignment.x()), ay = static_cast<float>(ring.alignment.y()),
                    az = static_cast<float>(ring.alignment.z());
        const float bx = static_cast<float>(ring.binormal.x()), by = static_cast<float>(ring.binormal.y()),
                    bz = static_cast<float>(ring.binormal.z());
        for (int j = 0; j < rv; ++j) {
            const float x = px[2 * j], y = px[2 * j + 1];
            const float u = nx[2 * j], v = nx[2 * j + 1];
            pos[0] = cx + ax * x + bx * y;
            pos[1] = cy + ay * x + by * y;
            pos[2] = cz + az * x + bz * y;
            nrm[0] = ax * u + bx * v;
            nrm[1] = ay * u + by * v;
            nrm[2] = az * u + bz * v;
            pos += 3;
            nrm += 3;
        }
    }
    const std::vector<Vec2>& corners = hose.profile().corners();
    for (int side = 0; side < 2; ++side) {
        const RingFrame& ring = side == 0 ? m_frames.front() : m_frames.back();
        const Vec3 normal = side == 0 ? Vec3(-ring.tangent) : ring.tangent;
        for (const Vec2& c : corners) {
            const Vec3 position = ring.center + c.x() * ring.alignment + c.y() * ring.binormal;
            for (int k = 0; k < 3; ++k) {
                pos[k] = static_cast<float>(position[k]);
                nrm[k] = static_cast<float>(normal[k]);
            }
            pos += 3;
            nrm += 3;
        }
    }
}

} // namespace chaintube
