// ChainTube formats — the project document (*.ctproj): scenes, hoses, attachments, presets.
//
// The file is JSON, schema in formats/schema/project.schema.json, version "1.7" (the format, its
// versions and migrations: formats/README.md, "The project file"):
//
//   { "format": "chaintube-project", "version": "1.7", "name": "…",
//     "scenes":          [ { "id", "path", "import": { "metresPerUnit"?, "upAxis"?,
//                            "chordalTolerance", "angularTolerance", "placement"? } } ],
//     "materialPresets": [ { "name", "description", "expansionCoefficient",
//                            "bendLimit": { "minBendRadius" | "deflectionAngle" } } ],
//     "hoses":           [ { "id", "name", "route": [[x,y,z]…], "length",               (1.3)
//                            "material": "<preset>" | {…},
//                            "profile": { "shape", …params }, "outerDiameter",
//                            "segmentCount" | "segmentLength", "colour": [r,g,b,a],
//                            "roughness", "attachments": [ { "scene", "node",
//                            "offset": { "translation": [x,y,z], "rotation": [x,y,z,w] },
//                            "points": [first, last] } ],
//                            "clips": [ { "scene", "node", "offset": {…}, "place",        (1.5)
//                            "hold": "sliding"|"sliding-turning", "slideMin"?, "slideMax"? } ],
//                            "gravity": { "enabled", "direction": [x,y,z] },   (1.2)
//                            "torsion": { "enabled", "twistLimit" },           (1.2)
//                            "fittingsAllowance",                               (1.6)
//                            "plugs": { "start"?, "end"? } } ],                 (1.7)
//     "poses":           [ { "scene", "node", "matrix": [16 numbers] } ],      (1.1)
//     "colliders":       [ { "scene", "node" } ],                               (1.2)
//     "motions":         [ { "id", "scene", "node", "kind": "hinge"|"slider", "axis": [x,y,z],
//                            "point": [x,y,z] (hinge only), "min", "max" } ],     (1.4)
//     "checks":          { "clearance"? },                                     (1.6)
//     "sockets":         [ { "id", "scene", "node", "position": [x,y,z],          (1.7)
//                            "axis": [x,y,z], "captureRadius", "captureAngle", "tag" } ],
//     "export":          { "format": "glb"|"gltf", "path", "includeScene" } }
//
// Version 1.0 files have no "poses" (read as none; ProjectLoadReport::migrated). Files before
// 1.2 have no "gravity", "torsion" (read as off) and no "colliders" (read as none). A hose's
// "gravity" / "torsion" is written only when it differs from the default (off, direction
// [0, -1, 0], twist limit 0.1 rad), and read as that default when absent. Files before 1.3 have
// no hose "length": each hose gets the length of the hose laid along its route
// (routeRestLength()), so that it keeps that length when its route is edited later. Files before
// 1.4 have no "motions" (read as none). Files before 1.5 have no hose "clips" (read as none; a
// hose without clips is written without the key). Files before 1.6 have no hose
// "fittingsAllowance" (read as 0; written only when not 0) and no "checks" (read as none: the
// checks use their defaults; written only when a threshold is set). Files before 1.7 have no
// "sockets" (read as none; written only when there is one) and no hose "plugs" (read as none;
// written only when an end has a tag).
//
// All lengths are metres, angles radians, positions world coordinates (+Y up).
#pragma once

#include "chaintube/formats/atomic_file.h"
#include "chaintube/formats/errors.h"
#include "chaintube/formats/paths.h"
#include "chaintube/formats/scene.h"
#include "chaintube/hose.h"
#include "chaintube/material.h"
#include "chaintube/profile.h"
#include "chaintube/types.h"

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace chaintube::formats {

/// The newest format version this code reads and the one it writes.
constexpr int kProjectFormatMajor = 1;
constexpr int kProjectFormatMinor = 7; ///< 1.1 added "poses" (NodePose); 1.2 per-hose
                                       ///< "gravity" and "torsion", "colliders" (ColliderNode);
                                       ///< 1.3 the hose's "length"; 1.4 "motions" (PartMotion);
                                       ///< 1.5 the hose's "clips" (HoseClip); 1.6 the hose's
                                       ///< "fittingsAllowance" and "checks" (CheckSettings);
                                       ///< 1.7 "sockets" (Socket) and the hose's "plugs"
                                       ///< (HosePlugs)
/// File extension of project files.
constexpr const char* kProjectExtension = ".ctproj";

/// How a scene file is imported (maps to ImportOptions).
struct SceneImportSettings
{
    std::optional<double> metresPerUnit; ///< unset: detected from the file (see SourceUnits)
    std::optional<UpAxis> upAxis;        ///< unset: detected
    double chordalTolerance = 1e-4;      ///< metres > 0 (STEP tessellation)
    double angularTolerance = 0.5;       ///< radians in (0, π] (STEP tessellation)
    /// Where the author placed the scene when importing it (format 1.3, "placement", written
    /// when not zero): world metres added to the translation of the scene's root node, after
    /// the unit and up-axis conversion. Part of the file pose: routes and attachments are
    /// where the placed scene is.
    Vec3 placement = Vec3::Zero();
    bool operator==(const SceneImportSettings& o) const
    {
        return metresPerUnit == o.metresPerUnit && upAxis == o.upAxis &&
               chordalTolerance == o.chordalTolerance && angularTolerance == o.angularTolerance &&
               placement == o.placement;
    }
};

/// A CAD scene the hoses are laid in.
struct SceneReference
{
    std::string id;   ///< unique within the project; attachments refer to it
    std::string path; ///< as written: relative, absolute or "root:rest" (see paths.h)
    SceneImportSettings import;
    bool operator==(const SceneReference& o) const
    {
        return id == o.id && path == o.path && import == o.import;
    }
};

/// A named material with datasheet-like values.
struct MaterialPreset
{
    std::string name; ///< unique within the project, e.g. "PVC hose"
    std::string description;
    Material material;
    bool operator==(const MaterialPreset& o) const
    {
        return name == o.name && description == o.description && material == o.material;
    }
};

/// The four presets new projects start with: "PVC hose", "rubber hose", "braided steel hose",
/// "cable bundle" (expansion and minimum bend radius typical of datasheets for ~20 mm hoses).
std::vector<MaterialPreset> standardMaterialPresets();

/// Name of a project material preset.
struct PresetName
{
    std::string name;
    bool operator==(const PresetName& o) const { return name == o.name; }
};
/// A hose's material: a preset of the project, or inline values.
using MaterialChoice = std::variant<PresetName, Material>;

/// Cross-section of a hose. Only the fields of `shape` are meaningful (and compared, written):
/// Circle {sides} with radius outerDiameter/2; Ellipse {semiAxisX, semiAxisY, sides};
/// Rectangle {width, height}; RoundedRectangle {width, height, cornerRadius, cornerSegments};
/// Polygon {points, smoothAngle}. Ranges as in chaintube::Profile.
struct ProfileSpec
{
    Profile::Shape shape = Profile::Shape::Circle;
    int sides = 16;
    double semiAxisX = 0.01, semiAxisY = 0.01;
    double width = 0.02, height = 0.01;
    double cornerRadius = 0.002;
    int cornerSegments = 4;
    std::vector<Vec2> points;
    double smoothAngle = 0.0;
    bool operator==(const ProfileSpec& o) const;
    bool operator!=(const ProfileSpec& o) const { return !(*this == o); }
};

/// A run of axis points fixed to a scene node.
struct HoseAttachment
{
    std::string scene; ///< SceneReference::id
    std::string node;  ///< SceneNode::path, e.g. "/ROOT/node_1/node_1_11/Piston_123-844_0_Parts_1"
    /// Frame of the attachment in the node's (rigid) world frame: attach frame =
    /// scene.worldFrame(node) * offset. Rotation is stored as written (unit within 1e-6).
    Frame offset;
    int firstPoint = 0; ///< inclusive axis-point range, 0 ≤ first ≤ last
    int lastPoint = 0;
    bool operator==(const HoseAttachment& o) const;
};

/// A clip (guide) on a scene node that the hose passes through and slides through
/// (Hose::addClip). Its frame is the node's (rigid) world frame times `offset`, as for an
/// attachment; where the hose is at the rest arc length `place` from its first point when it
/// is built gives the clip's centre and axis.
struct HoseClip
{
    std::string scene; ///< SceneReference::id
    std::string node;  ///< SceneNode::path
    Frame offset;
    double place = 0.0; ///< metres from the hose's first point, 0 ≤ place ≤ the hose's length
    Hold hold = Hold::Sliding; ///< Sliding or SlidingTurning
    /// End stops along the hose (metres from its first point); absent: the hose's ends.
    std::optional<double> slideMin;
    std::optional<double> slideMax;
    bool operator==(const HoseClip& o) const;
};

/// (1.7) The plug tags of a hose's two ends: an end fits a socket whose tag equals its plug
/// tag. Empty: that end has no plug (it fits no socket).
struct HosePlugs
{
    std::string start; ///< the end at the hose's first axis point
    std::string end;   ///< the end at its last axis point
    bool operator==(const HosePlugs& o) const { return start == o.start && end == o.end; }
    bool empty() const { return start.empty() && end.empty(); }
};

/// Colour, linear RGBA in [0, 1].
struct Rgba
{
    double r = 0.2, g = 0.2, b = 0.2, a = 1.0;
    bool operator==(const Rgba& o) const { return r == o.r && g == o.g && b == o.b && a == o.a; }
};

/// One hose as the author laid it out: its shape (the route) and its length are separate, so
/// that reshaping a hose never changes how long it is.
struct HoseDefinition
{
    std::string id;   ///< unique within the project
    std::string name; ///< for people; may repeat
    /// The shape at the file pose: world metres, ≥ 2 points, consecutive points distinct. A
    /// route with one point per axis point that is already a valid shape of the hose (every
    /// segment in its stretch band, every joint within its bend limit) is the axis itself (a
    /// committed drag stores the shape so); any other route is rounded with the minimum bend
    /// radius and sampled at equal arc length (Hose::alongRoute). See buildHose().
    std::vector<Vec3> route;
    /// The hose's rest length (metres > 0, finite): every segment's rest length is length /
    /// segments, whatever shape the route gives it (buildHose()). Unset: the length of the hose
    /// laid along its route (routeRestLength()), which then follows route edits; the reader sets it
    /// for files before 1.3, the editor for every hose it creates.
    std::optional<double> length;
    MaterialChoice material = PresetName{"PVC hose"};
    ProfileSpec profile;
    double outerDiameter = 0.02; ///< metres > 0
    /// Axis resolution: segmentCount (1 … 1,000,000) if > 0, else segmentLength (metres > 0).
    int segmentCount = 12;
    double segmentLength = 0.02;
    Rgba colour;
    double roughness = 0.5; ///< [0, 1], PBR
    std::vector<HoseAttachment> attachments;
    std::vector<HoseClip> clips; ///< (1.5) built after the attachments, in this order
    /// Gravity sag while the hose runs (HoseSpec::gravity): on/off and the world direction
    /// (need not be unit; finite, non-zero). Off unless the file says otherwise.
    Gravity gravity;
    /// Torsion (HoseSpec::torsion): on/off and the twist limit, radians per joint in (0, π].
    Torsion torsion;
    /// (1.6) The length the hose's end fittings take up beyond its rest length, both ends
    /// together (metres ≥ 0, finite): the hose is cut to length + fittingsAllowance
    /// (exporting::lengthReport). Not part of the model: building, export and the runtime
    /// ignore it. Written only when not 0.
    double fittingsAllowance = 0.0;
    HosePlugs plugs; ///< (1.7) written only when an end has a tag
    bool operator==(const HoseDefinition& o) const;
    bool operator!=(const HoseDefinition& o) const { return !(*this == o); }
};

/// A scene node moved or rotated by the author (a pose override): the node's parent ← node
/// transform replaces the one the scene file gives. Hoses are still defined at the file pose
/// (routes, attachment offsets); buildHose() builds them there and then moves their
/// attachments to the posed node frames, so the hoses follow the part as in the editor.
struct NodePose
{
    std::string scene; ///< SceneReference::id
    std::string node;  ///< SceneNode::path
    /// parent ← node, metres; affine (last row 0 0 0 1), finite, invertible 3×3 block.
    /// Written as "matrix": 16 numbers, column-major (glTF's order).
    Mat4 localTransform = Mat4::Identity();
    bool operator==(const NodePose& o) const
    {
        return scene == o.scene && node == o.node && localTransform == o.localTransform;
    }
};

/// A scene node flagged as a collider: hoses stay outside its mesh, except a hose
/// attached to that node or to a node under it (formats/collider_exemption.h). The export
/// lists it in the runtime descriptor (glTF node index) with its mesh.
struct ColliderNode
{
    std::string scene; ///< SceneReference::id
    std::string node;  ///< SceneNode::path
    bool operator==(const ColliderNode& o) const { return scene == o.scene && node == o.node; }
};

/// A part that moves through a range (format 1.4): a hinge turns a scene node about an axis
/// through a point, a slider moves it along an axis. The node carries its children, and the
/// hoses attached to them follow (formats/motion.h, exporting::sweepMotions). Value 0 is the
/// node's pose in the project (the file pose with project.poses applied); the axis and point
/// are world coordinates at that pose and travel with a moving ancestor (a hinge on a slider's
/// carriage moves with the carriage).
struct PartMotion
{
    enum class Kind {
        Hinge, ///< rotation by the value (radians, right-handed about `axis`) through `point`
        Slider ///< translation by the value (metres) along `axis`
    };
    std::string id;    ///< unique within the project; reports name the motion by it
    std::string scene; ///< SceneReference::id
    std::string node;  ///< SceneNode::path; at most one motion per (scene, node)
    Kind kind = Kind::Hinge;
    /// World direction, as written: finite, length > 1e-9, need not be unit (it is normalised
    /// where used).
    Vec3 axis = Vec3::UnitY();
    /// Hinge: a world point on the axis (metres, finite). Not written, read or compared for a
    /// slider.
    Vec3 point = Vec3::Zero();
    /// The range: radians in [−2π, 2π] for a hinge, metres (finite) for a slider;
    /// minimum ≤ 0 ≤ maximum (the project's pose lies in the range) and minimum < maximum.
    double minimum = 0.0;
    double maximum = 0.0;
    bool operator==(const PartMotion& o) const;
    bool operator!=(const PartMotion& o) const { return !(*this == o); }
};

/// "hinge" or "slider", as written in the file.
const char* toString(PartMotion::Kind kind);

/// (1.7) A coupling on a part that a hose end can be plugged into at runtime: a point with an
/// axis (the direction a plugged end points out of the part along), a capture zone and a tag.
/// Position and axis are in the node's (rigid) world frame at the file pose, as a
/// HoseAttachment's offset is: world position = scene.worldFrame(node) * position, so the
/// socket moves with its part (poses, motions, the runtime's node transforms). An end of a
/// hose fits the socket when its plug tag (HosePlugs) equals `tag`.
struct Socket
{
    std::string id;               ///< unique within the project; the runtime names the socket by it
    std::string scene;            ///< SceneReference::id
    std::string node;             ///< SceneNode::path of the part it sits on
    Vec3 position = Vec3::Zero(); ///< metres, in the node's frame (finite)
    /// In the node's frame, as written: finite, length > 1e-9, need not be unit (it is
    /// normalised where used).
    Vec3 axis = Vec3::UnitY();
    /// A released end whose tip lies within this distance of `position` may snap in (metres,
    /// finite, > 0).
    double captureRadius = 0.03;
    /// ... and whose direction lies within this angle of the axis (radians in (0, π]).
    double captureAngle = 0.5;
    std::string tag; ///< non-empty; which plugs fit (HosePlugs)
    bool operator==(const Socket& o) const;
    bool operator!=(const Socket& o) const { return !(*this == o); }
};

/// The project's own thresholds for its checks (format 1.6, "checks"): what `chaintube check`
/// uses without options and the editor's Problems panel shows and edits.
struct CheckSettings
{
    /// Clearance threshold, metres ≥ 0 (finite): a hose closer than this to a scene object is
    /// a violation. Unset: kDefaultClearance.
    std::optional<double> clearance;
    bool operator==(const CheckSettings& o) const { return clearance == o.clearance; }
};
/// The clearance threshold of a project that sets none (metres): 5 mm.
constexpr double kDefaultClearance = 0.005;

struct ExportSettings
{
    std::string format = "glb"; ///< "glb" or "gltf"
    std::string path;           ///< project path of the output ("" = next to the project)
    bool includeScene = true;   ///< export the CAD scene with the hoses
    bool operator==(const ExportSettings& o) const
    {
        return format == o.format && path == o.path && includeScene == o.includeScene;
    }
};

/// The in-memory project. save → load reproduces it exactly (operator==).
struct Project
{
    std::string name;
    std::vector<SceneReference> scenes;
    std::vector<MaterialPreset> materialPresets;
    std::vector<HoseDefinition> hoses;
    /// Pose overrides, at most one per (scene, node), in the order written.
    std::vector<NodePose> poses;
    /// Collider nodes, at most one entry per (scene, node), in the order written.
    std::vector<ColliderNode> colliders;
    /// Moving parts (1.4), at most one per (scene, node), in the order written.
    std::vector<PartMotion> motions;
    CheckSettings checks; ///< (1.6)
    /// Sockets (1.7), ids unique, in the order written.
    std::vector<Socket> sockets;
    ExportSettings exportSettings;

    /// An empty project with standardMaterialPresets().
    static Project withStandardPresets(std::string name);

    const MaterialPreset* findPreset(std::string_view presetName) const;
    const SceneReference* findScene(std::string_view sceneId) const;
    const Socket* findSocket(std::string_view socketId) const;
    /// The hose's material, its preset looked up. Throws InvalidArgument for an unknown preset.
    Material materialOf(const HoseDefinition& hose) const;

    bool operator==(const Project& o) const;
    bool operator!=(const Project& o) const { return !(*this == o); }
};

struct ProjectLoadOptions
{
    /// Named roots for "root:path" scene paths. Paths naming a root that is not in the map are
    /// accepted at load (checked only syntactically) and fail in resolveScenePath().
    NamedRoots roots;
};

/// What loading found besides the project.
struct ProjectLoadReport
{
    std::string fileVersion; ///< as written, e.g. "0.9"
    bool migrated = false;   ///< an older layout was converted to the current one
                             ///< (0.9 → 1.x; 1.0 → 1.1: no "poses", read as none;
                             ///< before 1.2: gravity/torsion off, no colliders;
                             ///< before 1.3: each hose's length set to routeRestLength();
                             ///< before 1.4: no "motions", read as none;
                             ///< before 1.5: no clips; before 1.6: no "checks";
                             ///< before 1.7: no "sockets", no plugs)
    /// Keys a newer minor version added that this reader does not know (ignored), as pointers.
    std::vector<std::string> ignoredKeys;
};

/// Reads and validates a project file. Every problem throws ProjectFormatError naming the file,
/// the JSON pointer and what was expected: malformed JSON (with line/column), wrong types,
/// NaN/Inf or out-of-range numbers, unknown keys, duplicate ids, unknown presets or scene ids,
/// overlapping attachment ranges, motions with an unknown kind, a zero axis or an empty range,
/// sockets with a zero axis, a capture radius ≤ 0 or a capture angle outside (0, π],
/// paths that escape the project folder (see paths.h), and a major version newer than
/// kProjectFormatMajor. Version 0.9 files are migrated. Throws FileError if the file cannot be
/// read.
Project loadProject(const std::filesystem::path& file, const ProjectLoadOptions& options = {},
                    ProjectLoadReport* report = nullptr);

/// Same as loadProject() on text already in memory; `file` is used for messages and its folder
/// for resolving relative paths.
Project parseProject(std::string_view text, const std::filesystem::path& file,
                     const ProjectLoadOptions& options = {}, ProjectLoadReport* report = nullptr);

/// The canonical text of a project: fixed key order, 2-space indentation, shortest round-trip
/// numbers, '\n' line ends, final newline. loadProject → serialiseProject gives back a
/// canonical file byte for byte.
std::string serialiseProject(const Project& project);

/// Writes the canonical text atomically (see writeFileAtomically). The project is validated
/// first (as loadProject would, relative to the target's folder); an invalid project throws
/// ProjectFormatError and nothing is written. Paths are written as they are, not rebased: a
/// project saved into another folder goes through rebaseProject() first.
void saveProject(const Project& project, const std::filesystem::path& file,
                 const ProjectLoadOptions& validation = {}, const AtomicWriteOptions& write = {});

/// The project as it must be written at `toFile` when it was read from (or last saved at)
/// `fromFile` (Save As): every path it holds — each scene's "path" and the export target
/// "export"/"path" ("" stays "": next to the project) — re-expressed with rebaseProjectPath(),
/// so it names the same file from the new folder: relative when the file lies inside the new
/// folder, else absolute; named-root paths unchanged. Textures are not project paths: a scene
/// file names its own, relative to itself, and they move with it. The same folder gives the
/// project back unchanged. Throws PathError for a relative path that leaves fromFile's folder.
Project rebaseProject(Project project, const std::filesystem::path& fromFile,
                      const std::filesystem::path& toFile);

/// Absolute path of a project's scene file. Throws PathError (escaping path, unknown root).
std::filesystem::path resolveScenePath(const SceneReference& scene,
                                       const std::filesystem::path& projectFile,
                                       const NamedRoots& roots);

} // namespace chaintube::formats
