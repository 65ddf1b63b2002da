// ChainTube — the hose surface: one ring per axis point on the bisector plane, twist-corrected.
#pragma once

#include "chaintube/hose.h"

#include <cstdint>
#include <span>
#include <vector>

namespace chaintube {

/// Orientation of one ring. tangent is the normal of the ring plane (the bisector plane of the
/// two adjacent segments, pointing along the hose); alignment is the paper's alignment vector
/// (the ring's surface origin, u = 0), binormal = tangent × alignment. The three form a
/// right-handed orthonormal basis, so a ring vertex with profile coordinates (x, y) is at
/// center + x·alignment + y·binormal. As a rotation: columns (alignment, binormal, tangent).
struct RingFrame
{
    Vec3 center;
    Vec3 tangent;
    Vec3 alignment;
    Vec3 binormal;
    Quat rotation() const;
};

/// Where the first ring's twist comes from: the first ring's tangent and alignment in the
/// previous frame. A zero alignment means "none yet".
struct TwistSeed
{
    Vec3 tangent = Vec3::Zero();
    Vec3 alignment = Vec3::Zero();

    /// Torsion (HoseSpec::torsion): per attachment, a direction fixed in the attachment's
    /// frame and its roll about the hose axis, unwrapped from frame to frame so that turning an
    /// attachment by several turns accumulates.
    struct AttachmentRoll
    {
        int id = 0;
        Vec3 reference = Vec3::Zero(); ///< in the attachment frame's coordinates
        double roll = 0.0;             ///< radians, relative to when torsion first saw it
    };
    std::vector<AttachmentRoll> rolls;
};

/// Computes ring frames (centres in the hose's local coordinates, see Hose::localPoints()).
///
/// Ring plane (paper eq. 1): the bisector plane of the adjacent segments, i.e. its normal is
/// normalize(d_{i−1} + d_i) for unit segment directions d; end rings are perpendicular to their
/// segment. Where the bisector is undefined (a fold-back of 180°, |d_{i−1} + d_i| < 1e-9) the
/// normal is the previous ring's normal made perpendicular to d_i; if that also vanishes, the
/// previous ring's alignment vector.
///
/// Twist correction (the paper's alignment vectors): each ring's alignment is the previous
/// ring's carried by the rotation-minimising double-reflection method (Wang et al. 2008),
/// which stays defined on straight runs where the paper's cross product n_p vanishes. The first
/// ring's alignment is carried from the previous frame (`seed`, updated in place) by the
/// smallest rotation taking the old first tangent to the new one, so rings do not pop between
/// frames; if the first tangent reversed exactly, the old alignment is projected instead. With
/// no seed yet: world +Y projected onto the first ring plane, or +X if the hose starts along Y.
///
/// Torsion (HoseSpec::torsion on; beyond the paper): the rings above are the torsion-free
/// shape. Each attachment's roll is the angle about the hose axis between that shape's
/// alignment at the attachment's first ring and a direction fixed in the attachment's frame
/// (taken from that alignment when torsion first sees the attachment, so it starts at 0);
/// turning an attachment about the hose axis changes it, bending it along with the hose barely
/// does. Every ring of an attachment rolls by its roll; between two attachments the difference
/// is spread evenly over the joints between them (the least largest twist per joint); beyond
/// the outermost attachments the free ends roll with their nearest attachment (a free end
/// does not twist). Twist per joint above HoseSpec::torsion.twistLimit cannot be met by
/// spreading: it is kept (the attachments are fixed) and reported by twistViolation. Without
/// attachments nothing rolls. Returns the largest twist per joint (radians).
double computeRingFrames(const Hose& hose, TwistSeed& seed, std::vector<RingFrame>& frames);

/// Static part of a hose's triangle mesh: depends only on the point count and profile.
///
/// Vertex order: ring i (0 ≤ i < rings) has profile.vertexCount() vertices (the last one is
/// the UV seam, at the same place as the first); then the start cap (profile.vertexCount() − 1
/// vertices) and the end cap (same count). Triangles are counter-clockwise seen from outside.
struct SurfaceTopology
{
    int ringCount = 0;
    int ringVertexCount = 0; ///< per ring, including the seam vertex
    int capVertexCount = 0;  ///< per cap
    int vertexCount = 0;
    std::vector<std::uint32_t> indices;
    /// u around the profile (0 … 1 by arc length), v along the axis in metres of rest length.
    std::vector<float> uvs; ///< 2 per vertex
    /// Which ring (= axis point = joint) each vertex belongs to.
    std::vector<std::uint32_t> vertexRing;

    static SurfaceTopology build(const Hose& hose);
};

/// The evolving surface of one hose: ring frames in double, vertex buffers in float.
///
/// update() recomputes frames and vertices only when the hose's revision changed since the
/// last call (a hose whose inputs did not change costs one integer compare).
class HoseSurface
{
public:
    explicit HoseSurface(const Hose& hose);

    /// Returns true if anything was recomputed.
    bool update(const Hose& hose);
    /// Force recomputation on the next update() (e.g. after the profile changed).
    void invalidate() { m_seenRevision = 0; }

    const SurfaceTopology& topology() const { return m_topology; }
    const std::vector<RingFrame>& frames() const { return m_frames; }
    /// Float positions, 3 per vertex, in metres relative to hose.origin() (add the origin back
    /// in double, e.g. in the model matrix, for hoses far from the world origin).
    std::span<const float> positions() const { return {m_positions.data(), 3 * vertexCount()}; }
    /// Unit normals, 3 per vertex (rigidly attached to the ring, like the positions).
    std::span<const float> normals() const { return {m_normals.data(), 3 * vertexCount()}; }
    size_t vertexCount() const { return static_cast<size_t>(m_topology.vertexCount); }
    const TwistSeed& twistSeed() const { return m_seed; }
    /// Torsion: the largest twist per joint (radians) and how far it exceeds the hose's
    /// twist limit (0 = within; always 0 with torsion off). See computeRingFrames().
    double maxTwistPerJoint() const { return m_maxTwist; }
    double twistViolation() const;
    void setTwistSeed(const TwistSeed& seed) { m_seed = seed; }

private:
    void rebuildTopology(const Hose& hose);
    void writeCaps(const Hose& hose);

    SurfaceTopology m_topology;
    std::vector<RingFrame> m_frames;
    // Vertex buffers carry a few floats of slack at the end: the vectorised ring kernel writes
    // whole 8-float blocks and lets the next ring (or cap) overwrite the excess.
    std::vector<float> m_positions;
    std::vector<float> m_normals;
    /// Profile x, y, normal x, normal y, each expanded to the xyz-interleaved layout of one
    /// ring (value of vertex k/3 at float k) and padded to a multiple of 8 floats.
    std::vector<float> m_expandedX, m_expandedY, m_expandedNormalX, m_expandedNormalY;
    TwistSeed m_seed;
    std::uint64_t m_seenRevision = 0;
    double m_maxTwist = 0.0;
    double m_twistLimit = 0.0;
    int m_pointCount = 0;
    Profile m_profile;
};

} // namespace chaintube
