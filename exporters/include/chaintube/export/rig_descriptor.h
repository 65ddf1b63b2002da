// ChainTube runtime — the hose-rig descriptor: everything a runtime needs to run the hoses of an
// exported glTF without the project file.
//
// The descriptor is JSON (schema: formats/schema/descriptor.schema.json, version "1.5"). It is
// embedded in the glTF as the root extension CHAINTUBE_hose_rig (listed in extensionsUsed only,
// never in extensionsRequired, so viewers that do not know it still load the file) and written
// beside the glTF as <name>.hoses.json. Node and skin indices refer to that glTF.
//
// Units: lengths in metres, angles in radians, positions in glTF world coordinates (+Y up,
// right-handed), rotations as unit quaternions [x, y, z, w] (glTF order).
#pragma once

#include "chaintube/hose.h"
#include "chaintube/material.h"
#include "chaintube/profile.h"
#include "chaintube/types.h"

#include <array>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace chaintube::rig {

/// Name of the glTF root extension that carries the descriptor.
constexpr const char* kExtensionName = "CHAINTUBE_hose_rig";
/// Value of the descriptor's "format" member.
constexpr const char* kDescriptorFormat = "chaintube-hose-rig";
/// Newest descriptor version this code reads, and the one it writes.
constexpr int kDescriptorMajor = 1;
/// 1.1 added "static"; 1.2 "gravity", "torsion", "colliders"; 1.3 "motions"; 1.4 a hose's
/// "clips"; 1.5 "sockets" and a hose's "plugs"
constexpr int kDescriptorMinor = 5;

/// A glTF node transform: parent ← node = T · R · S.
struct NodeTransform
{
    Vec3 translation = Vec3::Zero();
    Quat rotation = Quat::Identity();
    Vec3 scale = Vec3::Ones();
};

/// The descriptor's (and the project's) name of a cross-section shape: "circle", "ellipse",
/// "rectangle", "roundedRectangle", "polygon". `chaintube info` prints the same names.
const char* shapeName(Profile::Shape shape);

/// The cross-section a hose was built with, in a form that rebuilds the same Profile.
struct CrossSection
{
    Profile::Shape shape = Profile::Shape::Circle;
    /// As Profile::parameters(): circle {radius, sides}; ellipse {semiAxisX, semiAxisY, sides};
    /// rectangle {width, height}; roundedRectangle {width, height, cornerRadius, cornerSegments};
    /// polygon {smoothAngle}. Metres, radians, counts as numbers.
    std::vector<double> parameters;
    std::vector<Vec2> polygonPoints; ///< polygon only: the outline (metres, ring plane)

    static CrossSection of(const Profile& profile);
    /// The Profile (identical to the one the hose was exported with). Throws InvalidArgument
    /// when the parameters are out of range or the wrong count for the shape.
    Profile build() const;
};

/// A run of axis points fixed to a glTF node (or to the world when node is −1).
struct RigAttachment
{
    int node = -1; ///< glTF node index; −1: fixed in world coordinates
    /// Attachment frame relative to the rigid part of the node's world transform (scale and
    /// shear removed): attachment frame = rigid(world(node)) · offset.
    Frame offset;
    /// The attachment's world frame at export (where the points were fixed).
    Frame frame;
    int firstPoint = 0; ///< inclusive axis-point range
    int lastPoint = 0;
};

/// A clip the hose slides through (1.4, Hose::addClip), on a glTF node (or the world when node
/// is −1). At export the hose passes the clip's centre `place` metres (rest arc length) from its
/// first point; rebuildHose() adds the clip there, on the exported axis.
struct RigClip
{
    int node = -1;
    Frame offset; ///< clip frame = rigid(world(node)) · offset
    Frame frame;  ///< the clip's world frame at export
    double place = 0.0;
    Hold hold = Hold::Sliding;
    double slideMin = 0.0; ///< end stops, metres from the first point; slideMax may be +inf
    double slideMax = std::numeric_limits<double>::infinity();
};

/// One exported hose.
struct RigHose
{
    std::string id;
    std::string name;
    /// Static: every axis point is fixed, all to one scene node (or all to the world), so the
    /// hose never deforms at run time. It is exported as a plain mesh (skin, rig = −1, no
    /// joints, no grabbable points) under that node; a runtime still moves it with the node.
    bool isStatic = false;
    /// glTF node with the mesh (skinned: at the scene root; static: a child of the attachment
    /// node), its skin, and the node grouping the joints. −1 for skin and rig when static.
    int meshNode = -1;
    int skin = -1;
    int rigNode = -1;
    /// Joint node per axis point, in axis order (pointCount entries). The joint's world transform
    /// is (ring centre, ring rotation) with rotation columns (alignment, binormal, tangent).
    std::vector<int> jointNodes;
    /// Axis points at export, world metres (pointCount ≥ 2 entries).
    std::vector<Vec3> axis;
    /// Rest length of each segment (metres, pointCount − 1 entries).
    std::vector<double> restLengths;
    double expansionCoefficient = 0.05; ///< [0, 1)
    /// The limit as authored: minimum bend radius (metres) or deflection angle (radians).
    BendLimit bendLimit;
    /// Per interior joint j = 1 … pointCount − 2 (entry j − 1): the deflection limit (radians,
    /// π = unlimited) and the bend radius it corresponds to (metres).
    std::vector<double> jointBendLimits;
    std::vector<double> jointMinBendRadii;
    double outerDiameter = 0.02; ///< metres
    CrossSection crossSection;
    std::vector<RigAttachment> attachments;
    /// Clips (1.4; absent in older files: none), after the attachments in the library's order.
    std::vector<RigClip> clips;
    /// Axis points a runtime may grab (the free ones), ascending.
    std::vector<int> grabbablePoints;
    std::array<double, 4> baseColour{0.2, 0.2, 0.2, 1.0}; ///< linear RGBA
    double roughness = 0.5;
    /// Gravity sag while running (HoseSpec::gravity): on/off and the world direction (glTF
    /// world, need not be unit; finite, non-zero). Absent in files before 1.2: off.
    Gravity gravity;
    /// Torsion (HoseSpec::torsion): on/off and the twist limit (radians per joint, (0, π]).
    /// Absent in files before 1.2: off.
    Torsion torsion;
    /// Plug tags of the first ("start") and last ("end") end (1.5; absent: none). An end fits a
    /// socket whose tag equals its plug tag; "" fits none.
    std::string plugStart;
    std::string plugEnd;

    int pointCount() const { return static_cast<int>(axis.size()); }
    Material material() const;
};

/// A moving part (1.3, from the project's motions): a glTF node that a hinge turns about an axis
/// through a point, or a slider moves along an axis, within a range. The runtime does not move
/// it: a scenario drives the node (HoseRuntime::setNodeTransform) and the hoses follow; the
/// descriptor says how far the part was designed to go. Value 0 is the exported pose: at value
/// v a point of the part at world p goes to R(axis, v)(p − point) + point (hinge, right-handed)
/// or p + v axis (slider).
struct RigMotion
{
    enum class Kind { Hinge, Slider };
    std::string id; ///< unique in the descriptor
    int node = -1;  ///< the glTF node the motion moves (with everything under it)
    Kind kind = Kind::Hinge;
    Vec3 axis = Vec3::UnitY(); ///< glTF world, unit length
    Vec3 point = Vec3::Zero(); ///< hinge: a glTF world point on the axis; slider: unused (0)
    double minimum = 0.0;      ///< radians (hinge, ≥ −2π) or metres (slider); ≤ 0
    double maximum = 0.0;      ///< radians (hinge, ≤ 2π) or metres (slider); ≥ 0, > minimum
};

/// "hinge" or "slider", as written in the descriptor.
const char* motionKindName(RigMotion::Kind kind);

/// A coupling on a part that a hose end may plug into (1.5, from the project's sockets), on a
/// glTF node (or the world when node is −1). Position and axis are in the rigid part of the
/// node's world transform, so the socket moves with the node: world position =
/// rigid(world(node)) · position, world axis = its rotation · axis.
struct RigSocket
{
    std::string id;               ///< unique in the descriptor
    int node = -1;                ///< glTF node index; −1: fixed in world coordinates
    std::string nodeName;         ///< the glTF node's name at export ("" for the world), for people
    Vec3 position = Vec3::Zero(); ///< metres, node frame
    Vec3 axis = Vec3::UnitY();    ///< unit, node frame: the direction out of the part
    Vec3 worldPosition = Vec3::Zero(); ///< glTF world at export
    Vec3 worldAxis = Vec3::UnitY();    ///< glTF world at export, unit
    double captureRadius = 0.03;       ///< metres > 0
    double captureAngle = 0.5;         ///< radians in (0, π]
    std::string tag;                   ///< non-empty; the plugs that fit (RigHose::plugStart/End)
};

struct HoseRigDescriptor
{
    std::string version = "1.5";
    std::string generator;
    std::vector<RigHose> hoses;
    /// glTF nodes flagged as colliders (1.2), ascending, each with a mesh: a runtime builds a
    /// rigid MeshCollider from each node's mesh (world scale baked in, placed by the rigid part
    /// of the node's world transform) and every hose stays outside the colliders except those
    /// that are one of its attachment nodes or an ancestor of one in the glTF node hierarchy
    /// (its ends sit in those; formats/collider_exemption.h).
    std::vector<int> colliders;
    /// Moving parts (1.3), in project order; absent in older files (none).
    std::vector<RigMotion> motions;
    /// Sockets (1.5), in project order, ids unique; absent in older files (none).
    std::vector<RigSocket> sockets;
};

/// The descriptor is malformed. what() is "<source>: <JSON pointer>: <what was expected>".
class DescriptorError : public Error
{
public:
    DescriptorError(std::string source, std::string pointer, std::string expected);
    const std::string& source() const { return m_source; }
    const std::string& pointer() const { return m_pointer; }

private:
    std::string m_source;
    std::string m_pointer;
};

/// Parses a descriptor from JSON text. `source` names the file (or "file.glb#CHAINTUBE_hose_rig")
/// in messages. Checks types, ranges and the hose invariants (array lengths agree with the
/// point count, attachment ranges inside the hose and not overlapping, grabbable points free,
/// unit quaternions, finite numbers). Throws DescriptorError; a newer major version is refused.
HoseRigDescriptor parseDescriptor(std::string_view json, const std::string& source);

/// The descriptor as JSON text (2-space indentation, shortest round-trip numbers, final newline).
/// Empty lists are written as [] (never null).
std::string serialiseDescriptor(const HoseRigDescriptor& descriptor);

/// Rebuilds the hose a descriptor entry describes, as it was at export: Hose::fromAxis(axis,
/// restLengths) with the material, diameter and cross-section (fromAxis(axis) when restLengths
/// does not have one entry per segment), then every attachment fixed at its exported world
/// frame, then every clip at its place and exported frame (the reader checks that each can be).
/// attachmentIds (optional) receives the library's id of each attachment, then of each clip. A hose
/// exported away from its rest shape (stretched or compressed; restLengthsMatch() tells) comes
/// back as it was, under the same strain, not relaxed at the exported shape. Throws
/// InvalidArgument.
Hose rebuildHose(const RigHose& hose, std::vector<int>* attachmentIds = nullptr);

/// True if the axis distances equal restLengths within 1e-9 (relative), i.e. the hose was
/// exported at its rest shape.
bool restLengthsMatch(const RigHose& hose);

/// True if every axis distance lies in its segment's stretch band, [rest (1 − e), rest (1 + e)]
/// (1e-9 relative), i.e. the hose was exported in a state its constraints allow. A hose whose
/// project route is stretched or compressed within the band (a committed drag, a length edit)
/// is exported so, and comes back so.
bool withinStretchBand(const RigHose& hose);

/// Problems a descriptor has in the context of its glTF:
/// joint/mesh/attachment/collider/motion/socket node indices outside [0, nodeCount), joints used
/// twice. Empty when consistent. Messages carry a pointer.
std::vector<std::string> checkAgainstGltf(const HoseRigDescriptor& descriptor, int nodeCount,
                                          int skinCount);

} // namespace chaintube::rig
