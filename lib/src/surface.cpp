#include "chaintube/surface.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

namespace chaintube {

namespace {
Vec3 perpendicularPart(const Vec3& v, const Vec3& unitAxis)
{
    return v - v.dot(unitAxis) * unitAxis;
}

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
    void resize(size_t n)
    {
        for (auto* v : {&x, &y, &z, &tx, &ty, &tz})
            v->resize(n);
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

__attribute__((target("avx2,fma"))) void normalizeAvx2(double* x, double* y, double* z,
                                                       size_t count)
{
    const __m256d one = _mm256_set1_pd(1.0);
    size_t i = 0;
    for (; i + 4 <= count; i += 4) {
        const __m256d vx = _mm256_loadu_pd(x + i), vy = _mm256_loadu_pd(y + i),
                      vz = _mm256_loadu_pd(z + i);
        const __m256d length2 =
            _mm256_fmadd_pd(vz, vz, _mm256_fmadd_pd(vy, vy, _mm256_mul_pd(vx, vx)));
        const __m256d inv = _mm256_div_pd(one, _mm256_sqrt_pd(length2));
        _mm256_storeu_pd(x + i, _mm256_mul_pd(vx, inv));
        _mm256_storeu_pd(y + i, _mm256_mul_pd(vy, inv));
        _mm256_storeu_pd(z + i, _mm256_mul_pd(vz, inv));
    }
    normalizeScalar(x + i, y + i, z + i, count - i);
}

bool cpuHasAvx512()
{
    static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
    return has;
}

/// As normalizeAvx2 without the square root and the division (both on the one divider, which
/// bounds the AVX2 loop): the 14-bit reciprocal square root estimate, refined by two Newton
/// steps (14 → 28 → 53 bits), is within an ulp or two of 1/sqrt. Ring frames ~14 % faster.
__attribute__((target("avx2,fma,avx512f,avx512vl"))) void normalizeAvx512(double* x, double* y,
                                                                          double* z, size_t count)
{
    const __m256d half = _mm256_set1_pd(0.5), threeHalves = _mm256_set1_pd(1.5);
    size_t i = 0;
    for (; i + 4 <= count; i += 4) {
        const __m256d vx = _mm256_loadu_pd(x + i), vy = _mm256_loadu_pd(y + i),
                      vz = _mm256_loadu_pd(z + i);
        const __m256d length2 =
            _mm256_fmadd_pd(vz, vz, _mm256_fmadd_pd(vy, vy, _mm256_mul_pd(vx, vx)));
        __m256d r = _mm256_rsqrt14_pd(length2);
        const __m256d h = _mm256_mul_pd(half, length2);
        for (int k = 0; k < 2; ++k)
            r = _mm256_mul_pd(r, _mm256_fnmadd_pd(_mm256_mul_pd(h, r), r, threeHalves));
        _mm256_storeu_pd(x + i, _mm256_mul_pd(vx, r));
        _mm256_storeu_pd(y + i, _mm256_mul_pd(vy, r));
        _mm256_storeu_pd(z + i, _mm256_mul_pd(vz, r));
    }
    normalizeScalar(x + i, y + i, z + i, count - i);
}
} // namespace
#endif

namespace {
void normalize(double* x, double* y, double* z, size_t count)
{
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpuHasAvx512()) return normalizeAvx512(x, y, z, count);
    if (cpuHasAvx2()) return normalizeAvx2(x, y, z, count);
#endif
    normalizeScalar(x, y, z, count);
}
} // namespace

namespace {
/// Passes 1–2 of the ring frames (centres, bisector tangents) and the first alignment, carried
/// over from the previous frame through `seed`. Returns the first alignment.
Vec3 prepareRingFrames(const Hose& hose, TwistSeed& seed, std::vector<RingFrame>& frames)
{
    const std::vector<Vec3>& p = hose.localPoints();
    const size_t n = p.size();
    frames.resize(n);
    thread_local FrameScratch scratch;
    scratch.resize(n);
    // Raw pointers: the thread-local vectors' data pointers would otherwise be reloaded
    // through the TLS block in every iteration.
    double* const x = scratch.x.data();
    double* const y = scratch.y.data();
    double* const z = scratch.z.data();
    double* const tx = scratch.tx.data();
    double* const ty = scratch.ty.data();
    double* const tz = scratch.tz.data();
    const Vec3* const points = p.data();
    RingFrame* const out = frames.data();

    // Pass 1: unit segment directions d_i (segments have positive length: Lmin > 0).
    for (size_t i = 0; i + 1 < n; ++i) {
        x[i] = points[i + 1].x() - points[i].x();
        y[i] = points[i + 1].y() - points[i].y();
        z[i] = points[i + 1].z() - points[i].z();
    }
    normalize(x, y, z, n - 1);

    // Pass 2: ring plane normals, the bisectors normalize(d_{i−1} + d_i); end rings follow
    // their segment. Fold-backs (|d_{i−1} + d_i| ≈ 0) are mended afterwards, in order.
    tx[0] = x[0], ty[0] = y[0], tz[0] = z[0];
    tx[n - 1] = x[n - 2], ty[n - 1] = y[n - 2], tz[n - 1] = z[n - 2];
    bool foldBack = false;
    for (size_t i = 1; i + 1 < n; ++i) {
        tx[i] = x[i - 1] + x[i];
        ty[i] = y[i - 1] + y[i];
        tz[i] = z[i - 1] + z[i];
        foldBack |= tx[i] * tx[i] + ty[i] * ty[i] + tz[i] * tz[i] <= 1e-18;
    }
    if (n > 2) normalize(tx + 1, ty + 1, tz + 1, n - 2);
    for (size_t i = 0; i < n; ++i) {
        out[i].center = points[i];
        out[i].tangent = Vec3(tx[i], ty[i], tz[i]);
    }
    if (foldBack) {
        for (size_t i = 1; i + 1 < n; ++i) {
            const Vec3 in(x[i - 1], y[i - 1], z[i - 1]), next(x[i], y[i], z[i]);
            if ((in + next).squaredNorm() > 1e-18) continue;
            Vec3 t = perpendicularPart(out[i - 1].tangent, next);
            if (t.norm() < 1e-9) t = perpendicularPart(Vec3::UnitY(), next);
            if (t.norm() < 1e-9) t = perpendicularPart(Vec3::UnitX(), next);
            out[i].tangent = t.normalized();
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
            carried = seed.alignment * c + k.cross(seed.alignment) +
                      k * (k.dot(seed.alignment) / (1.0 + c));
        }
        a0 = perpendicularPart(carried, t0);
        a0 = a0.norm() > 1e-9 ? Vec3(a0.normalized()) : defaultAlignment(t0);
    }
    seed.tangent = t0;
    seed.alignment = a0;
    return a0;
}

/// Where a ring's vertices go (see RingWriter).
struct RingKernelInput
{
    size_t ringFloats; // 3 × vertices per ring
    const float* x;
    const float* y;
    const float* nx;
    const float* ny;
    float* positions;
    float* normals;
};

/// One step of the chain at ring i (> 0): u projected onto ring i's plane, or the double
/// reflection where that degenerates. u2 tracks |u|² (t is a unit vector).
[[gnu::always_inline]] inline void alignmentStep(const std::vector<RingFrame>& frames, size_t i,
                                                 Vec3& u, double& u2)
{
    const RingFrame& ring = frames[i];
    const Vec3& t = ring.tangent;
    const double along = u.dot(t);
    const double remaining = u2 - along * along;
    if (remaining > 1e-4 * u2) {
        u -= along * t;
        u2 = remaining;
        if (u2 < 1e-200) { // rescale long chains of strong bends
            u *= 1.0 / std::sqrt(u2);
            u2 = 1.0;
        }
        return;
    }
    const RingFrame& before = frames[i - 1];
    const Vec3 v1 = ring.center - before.center;
    const double b1 = v1.squaredNorm();
    Vec3 alignment = before.alignment;
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

/// A ring's unit alignment and binormal from the carried alignment u.
[[gnu::always_inline]] inline void finishRing(RingFrame& ring, const Vec3& u)
{
    ring.alignment = u * (1.0 / std::sqrt(u.squaredNorm()));
    ring.binormal = ring.tangent.cross(ring.alignment);
}

/// Pass 3, twist correction, with pass 4 (unit alignments and binormals). The alignment chain
/// is latency bound (one projection per ring depends on the last); the vertices are written
/// afterwards in a loop of their own (see HoseSurface::update for why not fused).
/// Fast path, the paper's own: project the previous alignment onto this ring plane.
/// Projection is linear, so the chain runs unnormalised (a short dependency chain) and each
/// ring takes a normalised copy. Where consecutive ring planes turn by nearly 90° the
/// projection degenerates; there the rotation-minimising double reflection (Wang et al. 2008)
/// takes over.
void alignRings(std::vector<RingFrame>& frames, const Vec3& a0)
{
    const size_t n = frames.size();
    if (n == 0) return;
    Vec3 u = a0;
    double u2 = 1.0;
    finishRing(frames[0], u);
    size_t i = 1;
    // Two rings a step where both projections are well conditioned: with a = u·t1, b = u·t2
    // and c = t1·t2, the second projection's (u − a t1)·t2 is b − a c, so both dot products
    // wait only for u and the chain is about two thirds as long as two single steps.
    while (i + 1 < n) {
        const Vec3& t1 = frames[i].tangent;
        const Vec3& t2 = frames[i + 1].tangent;
        const double a = u.dot(t1), b = u.dot(t2), c = t1.dot(t2);
        const double along2 = b - a * c;
        const double remaining1 = u2 - a * a, remaining2 = remaining1 - along2 * along2;
        if (remaining1 > 1e-4 * u2 && remaining2 > 1e-4 * remaining1 && remaining2 >= 1e-200) {
            const Vec3 u1 = u - a * t1;
            u = u1 - along2 * t2;
            u2 = remaining2;
            finishRing(frames[i], u1);
            finishRing(frames[i + 1], u);
            i += 2;
        } else {
            alignmentStep(frames, i, u, u2);
            finishRing(frames[i], u);
            ++i;
        }
    }
    if (i < n) {
        alignmentStep(frames, i, u, u2);
        finishRing(frames[i], u);
    }
}
} // namespace

namespace {
bool torsionActive(const Hose& hose)
{
    return hose.spec().torsion.enabled && !hose.attachments().empty();
}

/// Torsion on top of the torsion-free frames (see computeRingFrames in surface.h). Returns the
/// largest twist per joint.
double applyTorsion(const Hose& hose, TwistSeed& seed, std::vector<RingFrame>& frames)
{
    std::vector<const Hose::Attachment*> order;
    for (const Hose::Attachment& a : hose.attachments())
        if (a.hold != Hold::SlidingTurning) order.push_back(&a); // it lets the hose turn
    if (order.empty()) {
        seed.rolls.clear();
        return 0.0;
    }
    std::sort(order.begin(), order.end(), [](auto* x, auto* y) { return x->first < y->first; });
    std::vector<TwistSeed::AttachmentRoll> rolls;
    std::vector<double> roll(order.size());
    for (size_t k = 0; k < order.size(); ++k) {
        const Hose::Attachment& a = *order[k];
        const RingFrame& ring = frames[static_cast<size_t>(a.first)];
        auto known = std::find_if(seed.rolls.begin(), seed.rolls.end(),
                                  [&](const TwistSeed::AttachmentRoll& r) { return r.id == a.id; });
        TwistSeed::AttachmentRoll record;
        if (known == seed.rolls.end()) {
            record.id = a.id;
            record.reference = a.frame.rotation.conjugate() * ring.alignment;
        } else {
            record = *known;
            const Vec3 r = a.frame.rotation * record.reference;
            const Vec3 across = r - r.dot(ring.tangent) * ring.tangent;
            // A reference along the axis (the attachment turned the hose end-on to itself)
            // has no roll: keep the last one.
            if (across.norm() > 1e-9) {
                const double raw = std::atan2(ring.tangent.dot(ring.alignment.cross(across)),
                                              ring.alignment.dot(across));
                double delta = std::remainder(raw - record.roll, 2.0 * std::numbers::pi);
                record.roll += delta;
            }
        }
        roll[k] = record.roll;
        rolls.push_back(record);
    }
    seed.rolls = std::move(rolls);

    const int n = static_cast<int>(frames.size());
    double maxTwist = 0.0;
    auto rollAt = [&](int i) {
        if (i <= order.front()->last) return roll.front();
        for (size_t k = 0; k + 1 < order.size(); ++k) {
            const int from = order[k]->last, to = order[k + 1]->first;
            if (i <= from) return roll[k];
            if (i < to) return roll[k] + (roll[k + 1] - roll[k]) * (i - from) / double(to - from);
        }
        return roll.back();
    };
    for (size_t k = 0; k + 1 < order.size(); ++k) {
        const int joints = order[k + 1]->first - order[k]->last;
        if (joints > 0) maxTwist = std::max(maxTwist, std::abs(roll[k + 1] - roll[k]) / joints);
    }
    for (int i = 0; i < n; ++i) {
        const double phi = rollAt(i);
        if (phi == 0.0) continue;
        RingFrame& ring = frames[static_cast<size_t>(i)];
        const double c = std::cos(phi), sn = std::sin(phi);
        const Vec3 a = ring.alignment, b = ring.binormal;
        ring.alignment = c * a + sn * b;
        ring.binormal = c * b - sn * a;
    }
    return maxTwist;
}
} // namespace

double computeRingFrames(const Hose& hose, TwistSeed& seed, std::vector<RingFrame>& frames)
{
    const Vec3 a0 = prepareRingFrames(hose, seed, frames);
    alignRings(frames, a0);
    if (!torsionActive(hose)) {
        seed.rolls.clear();
        return 0.0;
    }
    return applyTorsion(hose, seed, frames);
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
            const std::uint32_t a = i * rv + j, b = a + 1, c = (i + 1) * rv + j + 1,
                                d = (i + 1) * rv + j;
            t.indices.insert(t.indices.end(), {a, b, c, a, c, d});
        }
    const auto startCap = static_cast<std::uint32_t>(t.ringCount) * rv;
    const auto endCap = startCap + static_cast<std::uint32_t>(t.capVertexCount);
    const std::vector<int>& cap = profile.capTriangles();
    for (size_t k = 0; k + 2 < cap.size(); k += 3) {
        const auto c0 = static_cast<std::uint32_t>(cap[k]),
                   c1 = static_cast<std::uint32_t>(cap[k + 1]),
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

HoseSurface::HoseSurface(const Hose& hose)
{
    update(hose);
}

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

namespace {
// Eight floats: GCC/Clang vector extensions, so one source serves every target (two SSE
// halves by default, one AVX register in the AVX2 clone below).
typedef float Float8 __attribute__((vector_size(32)));
typedef float Float4 __attribute__((vector_size(16)));
typedef double Double4 __attribute__((vector_size(32)));

// (By reference: passing or returning 32-byte vectors by value changes the ABI with AVX.)
[[gnu::always_inline]] inline void load8(Float8& v, const float* p)
{
    std::memcpy(&v, p, sizeof v);
}
[[gnu::always_inline]] inline void store8(float* p, const Float8& v)
{
    std::memcpy(p, &v, sizeof v);
}

/// Writes one ring's vertices and normals, eight floats at a time in the xyz-interleaved
/// layout: the ring's centre and axes are permuted into the three phases of the xyz pattern
/// (period 24 floats = 8 vertices). The last block spills up to 7 floats into the next ring
/// (written after this one) or the buffers' slack.
struct RingWriter
{
    RingKernelInput in;
    [[gnu::always_inline]] inline void operator()(size_t i, const RingFrame& ring) const
    {
        // One conversion per vector (x, y, z, 0 in doubles → floats), then one permutation
        // per phase (a single vpermps with AVX2).
        const Double4 cd = {ring.center.x(), ring.center.y(), ring.center.z(), 0.0};
        const Double4 ad = {ring.alignment.x(), ring.alignment.y(), ring.alignment.z(), 0.0};
        const Double4 bd = {ring.binormal.x(), ring.binormal.y(), ring.binormal.z(), 0.0};
        const Float4 c = __builtin_convertvector(cd, Float4);
        const Float4 a = __builtin_convertvector(ad, Float4);
        const Float4 b = __builtin_convertvector(bd, Float4);
        const Float8 cp[3] = {__builtin_shufflevector(c, c, 0, 1, 2, 0, 1, 2, 0, 1),
                              __builtin_shufflevector(c, c, 2, 0, 1, 2, 0, 1, 2, 0),
                              __builtin_shufflevector(c, c, 1, 2, 0, 1, 2, 0, 1, 2)};
        const Float8 ap[3] = {__builtin_shufflevector(a, a, 0, 1, 2, 0, 1, 2, 0, 1),
                              __builtin_shufflevector(a, a, 2, 0, 1, 2, 0, 1, 2, 0),
                              __builtin_shufflevector(a, a, 1, 2, 0, 1, 2, 0, 1, 2)};
        const Float8 bp[3] = {__builtin_shufflevector(b, b, 0, 1, 2, 0, 1, 2, 0, 1),
                              __builtin_shufflevector(b, b, 2, 0, 1, 2, 0, 1, 2, 0),
                              __builtin_shufflevector(b, b, 1, 2, 0, 1, 2, 0, 1, 2)};
        float* pos = in.positions + i * in.ringFloats;
        float* nrm = in.normals + i * in.ringFloats;
        const size_t blocks = (in.ringFloats + 7) / 8;
        size_t m = 0;
        // Unrolled by the xyz period (3 blocks) so the phase vectors stay in registers.
        for (; m + 3 <= blocks; m += 3) {
            block(pos, nrm, m, cp[0], ap[0], bp[0]);
            block(pos, nrm, m + 1, cp[1], ap[1], bp[1]);
            block(pos, nrm, m + 2, cp[2], ap[2], bp[2]);
        }
        if (m < blocks) block(pos, nrm, m, cp[0], ap[0], bp[0]);
        if (m + 1 < blocks) block(pos, nrm, m + 1, cp[1], ap[1], bp[1]);
    }

    [[gnu::always_inline]] inline void block(float* pos, float* nrm, size_t m, const Float8& c,
                                             const Float8& a, const Float8& b) const
    {
        Float8 x, y, nx, ny;
        load8(x, in.x + 8 * m);
        load8(y, in.y + 8 * m);
        load8(nx, in.nx + 8 * m);
        load8(ny, in.ny + 8 * m);
        const Float8 position = c + a * x + b * y, normal = a * nx + b * ny;
        store8(pos + 8 * m, position);
        store8(nrm + 8 * m, normal);
    }
};

void writeRings(const std::vector<RingFrame>& frames, const RingWriter& writer)
{
    for (size_t i = 0; i < frames.size(); ++i)
        writer(i, frames[i]);
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2,fma"))) void writeRingsAvx2(const std::vector<RingFrame>& frames,
                                                        const RingWriter& writer)
{
    for (size_t i = 0; i < frames.size(); ++i)
        writer(i, frames[i]);
}
__attribute__((target("avx2,fma,avx512f,avx512vl"))) void
writeRingsAvx512Vl(const std::vector<RingFrame>& frames, const RingWriter& writer)
{
    for (size_t i = 0; i < frames.size(); ++i)
        writer(i, frames[i]);
}
#endif
} // namespace

bool HoseSurface::update(const Hose& hose)
{
    if (m_seenRevision == hose.revision() && m_pointCount == hose.pointCount()) return false;
    if (m_pointCount != hose.pointCount() || !(m_profile == hose.profile()) ||
        m_profile.vertexCount() != hose.profile().vertexCount())
        rebuildTopology(hose);
    const RingWriter writer{{3 * static_cast<size_t>(m_topology.ringVertexCount),
                             m_expandedX.data(), m_expandedY.data(), m_expandedNormalX.data(),
                             m_expandedNormalY.data(), m_positions.data(), m_normals.data()}};
    m_twistLimit = hose.spec().torsion.twistLimit;
    // Frames first, then vertices, in two loops: on the project's AMD EPYC (Zen 4) machine this
    // is faster than fusing the ring writes into the latency-bound alignment chain (figures
    // under 331eb83 in tests/bench/PERFORMANCE-NOTES.md).
    m_maxTwist = computeRingFrames(hose, m_seed, m_frames);
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpuHasAvx512())
        writeRingsAvx512Vl(m_frames, writer);
    else if (cpuHasAvx2())
        writeRingsAvx2(m_frames, writer);
    else
        writeRings(m_frames, writer);
#else
    writeRings(m_frames, writer);
#endif
    writeCaps(hose);
    m_seenRevision = hose.revision();
    return true;
}

double HoseSurface::twistViolation() const
{
    return std::max(0.0, m_maxTwist - m_twistLimit);
}

void HoseSurface::writeCaps(const Hose& hose)
{
    const size_t ringFloats = 3 * static_cast<size_t>(m_topology.ringVertexCount);
    float* pos = m_positions.data() + m_frames.size() * ringFloats;
    float* nrm = m_normals.data() + m_frames.size() * ringFloats;
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
