#include "chaintube/surface.h"

#include <algorithm>
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

namespace {
// Structure-of-arrays scratch for the ring frame passes (per thread: no allocation per frame).
struct FrameScratch
{
    std::vector<double> x, y, z; // segment directions, then ring tangents
    std::vector<double> tx, ty, tz;
    std::vector<double> ax, ay, az;
    void resize(size_t n)
    {
        for (auto* v : {&x, &y, &z, &tx, &ty, &tz, &ax, &ay, &az}) v->resize(n);
    }
};

// Scales (x, y, z)[0, count) to unit length. Vectors of zero length become NaN; callers
// check lengths first where that can happen.
void normalizeScalar(double* x, double* y, double* z, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        const double inv = 1.0 / std::sqrt(x[i] * x[i] + y[i] * y[i] + z[i] * z[i]);
        x[i] *= inv;
        y[i] *= inv;
        z[i] *= inv;
    }
}
} // namespace

#if defined(__x86_64__) && defined(__GNUC__)
} // namespace chaintube
#include <immintrin.h>
namespace chaintube {
namespace {
bool cpuHasAvx2()
{
    static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    return has;
}

__attribute__((target("avx2,fma"))) void normalizeAvx2(double* x, double* y, double* z, size_t count)
{
    const __m256d one = _mm256_set1_pd(1.0);
    size_t i = 0;
    for (; i + 4 <= count; i += 4) {
        const __m256d vx = _mm256_loadu_pd(x + i), vy = _mm256_loadu_pd(y + i), vz = _mm256_loadu_pd(z + i);
        const __m256d length2 = _mm256_fmadd_pd(vz, vz, _mm256_fmadd_pd(vy, vy, _mm256_mul_pd(vx, vx)));
        const __m256d inv = _mm256_div_pd(one, _mm256_sqrt_pd(length2));
        _mm256_storeu_pd(x + i, _mm256_mul_pd(vx, inv));
        _mm256_storeu_pd(y + i, _mm256_mul_pd(vy, inv));
        _mm256_storeu_pd(z + i, _mm256_mul_pd(vz, inv));
    }
    normalizeScalar(x + i, y + i, z + i, count - i);
}
} // namespace
#endif

namespace {
void normalize(double* x, double* y, double* z, size_t count)
{
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpuHasAvx2()) return normalizeAvx2(x, y, z, count);
#endif
    normalizeScalar(x, y, z, count);
}
} // namespace

void computeRingFrames(const Hose& hose, TwistSeed& seed, std::vector<RingFrame>& frames)
{
    const std::vector<Vec3>& p = hose.localPoints();
    const size_t n = p.size();
    frames.resize(n);
    thread_local FrameScratch s;
    s.resize(n);

    // Pass 1: unit segment directions d_i (segments have positive length: Lmin > 0).
    for (size_t i = 0; i + 1 < n; ++i) {
        s.x[i] = p[i + 1].x() - p[i].x();
        s.y[i] = p[i + 1].y() - p[i].y();
        s.z[i] = p[i + 1].z() - p[i].z();
    }
    normalize(s.x.data(), s.y.data(), s.z.data(), n - 1);

    // Pass 2: ring plane normals, the bisectors normalize(d_{i−1} + d_i); end rings follow
    // their segment. Fold-backs (|d_{i−1} + d_i| ≈ 0) are mended afterwards, in order.
    s.tx[0] = s.x[0], s.ty[0] = s.y[0], s.tz[0] = s.z[0];
    s.tx[n - 1] = s.x[n - 2], s.ty[n - 1] = s.y[n - 2], s.tz[n - 1] = s.z[n - 2];
    bool foldBack = false;
    for (size_t i = 1; i + 1 < n; ++i) {
        s.tx[i] = s.x[i - 1] + s.x[i];
        s.ty[i] = s.y[i - 1] + s.y[i];
        s.tz[i] = s.z[i - 1] + s.z[i];
        foldBack |= s.tx[i] * s.tx[i] + s.ty[i] * s.ty[i] + s.tz[i] * s.tz[i] <= 1e-18;
    }
    if (n > 2) normalize(s.tx.data() + 1, s.ty.data() + 1, s.tz.data() + 1, n - 2);
    for (size_t i = 0; i < n; ++i) {
        frames[i].center = p[i];
        frames[i].tangent = Vec3(s.tx[i], s.ty[i], s.tz[i]);
    }
    if (foldBack) {
        for (size_t i = 1; i + 1 < n; ++i) {
            const Vec3 in(s.x[i - 1], s.y[i - 1], s.z[i - 1]), out(s.x[i], s.y[i], s.z[i]);
            if ((in + out).squaredNorm() > 1e-18) continue;
            Vec3 t = perpendicularPart(frames[i - 1].tangent, out);
            if (t.norm() < 1e-9) t = perpendicularPart(Vec3::UnitY(), out);
            if (t.norm() < 1e-9) t = perpendicularPart(Vec3::UnitX(), out);
            frames[i].tangent = t.normalized();
        }
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
    seed.tangent = t0;
    seed.alignment = a0;

    // Pass 3, twist correction. Fast path, the paper's own: project the previous alignment
    // onto this ring plane. Projection is linear, so the chain runs unnormalised (a short
    // dependency chain) and is normalised in pass 4. Where consecutive ring planes turn by
    // nearly 90° the projection degenerates; there the rotation-minimising double
    // reflection (Wang et al. 2008) takes over.
    Vec3 u = a0;
    double u2 = 1.0;
    s.ax[0] = u.x(), s.ay[0] = u.y(), s.az[0] = u.z();
    for (size_t i = 1; i < n; ++i) {
        const Vec3& t = frames[i].tangent;
        const double along = u.dot(t);
        const double remaining = u2 - along * along;
        if (remaining > 1e-4 * u2) {
            u -= along * t;
            u2 = remaining;
            if (u2 < 1e-200) { // rescale long chains of strong bends
                u *= 1.0 / std::sqrt(u2);
                u2 = 1.0;
            }
        } else {
            const RingFrame& before = frames[i - 1];
            const Vec3 v1 = frames[i].center - before.center;
            const double b1 = v1.squaredNorm();
            Vec3 alignment = Vec3(s.ax[i - 1], s.ay[i - 1], s.az[i - 1]).normalized();
            Vec3 tangentL = before.tangent;
            if (b1 > 0.0) {
                alignment -= (2.0 / b1) * v1.dot(alignment) * v1;
                tangentL -= (2.0 / b1) * v1.dot(tangentL) * v1;
            }
            const Vec3 v2 = t - tangentL;
            const double b2 = v2.squaredNorm();
            if (b2 > 1e-30) alignment -= (2.0 / b2) * v2.dot(alignment) * v2;
            alignment = perpendicularPart(alignment, t);
            u = alignment.norm() > 1e-9 ? Vec3(alignment.normalized()) : defaultAlignment(t);
            u2 = 1.0;
        }
        s.ax[i] = u.x(), s.ay[i] = u.y(), s.az[i] = u.z();
    }

    // Pass 4: unit alignments and binormals.
    normalize(s.ax.data(), s.ay.data(), s.az.data(), n);
    for (size_t i = 0; i < n; ++i) {
        RingFrame& ring = frames[i];
        ring.alignment = Vec3(s.ax[i], s.ay[i], s.az[i]);
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
    const size_t ringFloats = 3 * static_cast<size_t>(profile.vertexCount());
    const size_t padded = (ringFloats + 7) / 8 * 8;
    m_expandedX.assign(padded, 0.0f);
    m_expandedY.assign(padded, 0.0f);
    m_expandedNormalX.assign(padded, 0.0f);
    m_expandedNormalY.assign(padded, 0.0f);
    for (size_t k = 0; k < ringFloats; ++k) {
        const size_t j = k / 3;
        m_expandedX[k] = static_cast<float>(profile.points()[j].x());
        m_expandedY[k] = static_cast<float>(profile.points()[j].y());
        m_expandedNormalX[k] = static_cast<float>(profile.normals()[j].x());
        m_expandedNormalY[k] = static_cast<float>(profile.normals()[j].y());
    }
    const size_t floats = 3 * static_cast<size_t>(m_topology.vertexCount) + 8;
    m_positions.assign(floats, 0.0f);
    m_normals.assign(floats, 0.0f);
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

namespace {
struct RingKernelInput
{
    const RingFrame* frames;
    size_t ringCount;
    size_t ringFloats; // 3 × vertices per ring
    const float* x;
    const float* y;
    const float* nx;
    const float* ny;
    float* positions;
    float* normals;
};

void writeRingsScalar(const RingKernelInput& in)
{
    for (size_t i = 0; i < in.ringCount; ++i) {
        const RingFrame& ring = in.frames[i];
        float c[3], a[3], b[3];
        for (int k = 0; k < 3; ++k) {
            c[k] = static_cast<float>(ring.center[k]);
            a[k] = static_cast<float>(ring.alignment[k]);
            b[k] = static_cast<float>(ring.binormal[k]);
        }
        float* pos = in.positions + i * in.ringFloats;
        float* nrm = in.normals + i * in.ringFloats;
        for (size_t k = 0; k < in.ringFloats; ++k) {
            const size_t axis = k % 3;
            pos[k] = c[axis] + a[axis] * in.x[k] + b[axis] * in.y[k];
            nrm[k] = a[axis] * in.nx[k] + b[axis] * in.ny[k];
        }
    }
}
} // namespace

#if defined(__x86_64__) && defined(__GNUC__)
} // namespace chaintube
#include <immintrin.h>
namespace chaintube {
namespace {
__attribute__((target("avx2,fma"), always_inline)) inline void
ringBlock(const RingKernelInput& in, float* pos, float* nrm, size_t m, __m256 c, __m256 a, __m256 b)
{
    const __m256 x = _mm256_loadu_ps(in.x + 8 * m), y = _mm256_loadu_ps(in.y + 8 * m);
    const __m256 nx = _mm256_loadu_ps(in.nx + 8 * m), ny = _mm256_loadu_ps(in.ny + 8 * m);
    _mm256_storeu_ps(pos + 8 * m, _mm256_fmadd_ps(b, y, _mm256_fmadd_ps(a, x, c)));
    _mm256_storeu_ps(nrm + 8 * m, _mm256_fmadd_ps(b, ny, _mm256_mul_ps(a, nx)));
}

// Eight floats at a time in the xyz-interleaved layout: the ring's centre and axes are
// permuted into the three phases of the xyz pattern (period 24 floats = 8 vertices).
__attribute__((target("avx2,fma"))) void writeRingsAvx2(const RingKernelInput& in)
{
    const __m256i phase0 = _mm256_setr_epi32(0, 1, 2, 0, 1, 2, 0, 1);
    const __m256i phase1 = _mm256_setr_epi32(2, 0, 1, 2, 0, 1, 2, 0);
    const __m256i phase2 = _mm256_setr_epi32(1, 2, 0, 1, 2, 0, 1, 2);
    const size_t blocks = (in.ringFloats + 7) / 8;
    for (size_t i = 0; i < in.ringCount; ++i) {
        const RingFrame& ring = in.frames[i];
        const __m256 c = _mm256_castps128_ps256(_mm256_cvtpd_ps(_mm256_setr_pd(
            ring.center.x(), ring.center.y(), ring.center.z(), 0.0)));
        const __m256 a = _mm256_castps128_ps256(_mm256_cvtpd_ps(_mm256_setr_pd(
            ring.alignment.x(), ring.alignment.y(), ring.alignment.z(), 0.0)));
        const __m256 b = _mm256_castps128_ps256(_mm256_cvtpd_ps(_mm256_setr_pd(
            ring.binormal.x(), ring.binormal.y(), ring.binormal.z(), 0.0)));
        const __m256 cp[3] = {_mm256_permutevar8x32_ps(c, phase0), _mm256_permutevar8x32_ps(c, phase1),
                              _mm256_permutevar8x32_ps(c, phase2)};
        const __m256 ap[3] = {_mm256_permutevar8x32_ps(a, phase0), _mm256_permutevar8x32_ps(a, phase1),
                              _mm256_permutevar8x32_ps(a, phase2)};
        const __m256 bp[3] = {_mm256_permutevar8x32_ps(b, phase0), _mm256_permutevar8x32_ps(b, phase1),
                              _mm256_permutevar8x32_ps(b, phase2)};
        float* pos = in.positions + i * in.ringFloats;
        float* nrm = in.normals + i * in.ringFloats;
        size_t m = 0;
        for (; m + 3 <= blocks; m += 3) {
            ringBlock(in, pos, nrm, m, cp[0], ap[0], bp[0]);
            ringBlock(in, pos, nrm, m + 1, cp[1], ap[1], bp[1]);
            ringBlock(in, pos, nrm, m + 2, cp[2], ap[2], bp[2]);
        }
        if (m < blocks) ringBlock(in, pos, nrm, m, cp[0], ap[0], bp[0]);
        if (m + 1 < blocks) ringBlock(in, pos, nrm, m + 1, cp[1], ap[1], bp[1]);
    }
}

} // namespace
#endif

void HoseSurface::writeVertices(const Hose& hose)
{
    RingKernelInput in{m_frames.data(),      m_frames.size(),        3 * static_cast<size_t>(m_topology.ringVertexCount),
                       m_expandedX.data(),   m_expandedY.data(),     m_expandedNormalX.data(),
                       m_expandedNormalY.data(), m_positions.data(), m_normals.data()};
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpuHasAvx2()) writeRingsAvx2(in);
    else writeRingsScalar(in);
#else
    writeRingsScalar(in);
#endif
    float* pos = m_positions.data() + m_frames.size() * in.ringFloats;
    float* nrm = m_normals.data() + m_frames.size() * in.ringFloats;
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
    // Clear the slack so the buffers' contents never depend on the kernel used.
    std::fill(m_positions.begin() + static_cast<long>(3 * vertexCount()), m_positions.end(), 0.0f);
    std::fill(m_normals.begin() + static_cast<long>(3 * vertexCount()), m_normals.end(), 0.0f);
}

} // namespace chaintube
