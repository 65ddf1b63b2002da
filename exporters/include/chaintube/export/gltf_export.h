// ChainTube export — a project (scene + hoses) as a glTF 2.0 hose rig.
//
// Output: GLB, or .gltf + .bin. The imported scenes' nodes (names, hierarchy, transforms) and
// meshes, plus every hose as a skinned mesh: one joint node (TRS, never matrix) per axis point
// whose world transform is (ring centre, ring rotation), every ring's vertices weighted 1.0 to
// their own joint, inverse bind matrices, the skinned-mesh node at the scene root. Joints of a
// segment fixed to a scene node are descendants of that node, so moving the node in any viewer
// carries the fixed segment:
//  * a hose fixed to one scene node only: every joint hangs under the hose's "<id> joints" node,
//    a child of that node (the joints' deepest common ancestor is the hose's own node: Blender
//    makes one armature per hose);
//  * a hose fixed to several scene nodes: the joints of each attached segment are children of
//    their node, the free joints hang under "<id> joints" below the deepest common ancestor of
//    the attachment nodes (Blender's armature sits at that ancestor; hoses whose paths from
//    their attachment nodes up to that ancestor share a node share one armature — no glTF
//    hierarchy can avoid it while moving a node still carries the segment fixed to it);
//  * a free hose (or one fixed to the world): "<id> joints" under the root node.
// Static hoses (every axis point fixed, all to one scene node or all to the world) never
// deform at run time: they are plain meshes (no skin, no joints) under that node (the root for
// the world) whose transform undoes the node's world transform at export, so the file looks
// the same and moving the node carries the mesh. All joints share the single root node named
// after the project. Metres, +Y up. One PBR material per hose (base colour, roughness,
// metallic 0).
//
// The runtime descriptor (rig_descriptor.h) is embedded as the root extension
// CHAINTUBE_hose_rig (extensionsUsed only) and written beside as <name>.hoses.json.
//
// Writes are atomic: all contents are built in memory, each file is written completely as
// <file>.partial (formats::writeFileAtomically), and only when all are on disk are they renamed
// over their targets, the glTF last. A failure while building or writing leaves a previous
// export's .glb/.gltf, .bin and .hoses.json as they were, and no .partial behind.
#pragma once

#include "chaintube/export/rig_descriptor.h"
#include "chaintube/formats/paths.h"
#include "chaintube/formats/project.h"
#include "chaintube/formats/scene.h"
#include "chaintube/hose.h"

#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace chaintube::exporting {

enum class Container {
    FromExtension, ///< ".glb" → Glb, ".gltf" → Gltf; anything else is an InvalidArgument
    Glb,
    Gltf, ///< JSON + <name>.bin beside it
};

/// A scene node a hose attachment is fixed to.
struct NodeRef
{
    int scene = -1; ///< index into the scenes passed to exportRig(); −1: fixed in world
    int node = -1;  ///< index into that scene's ImportedScene::nodes
};

struct ExportOptions
{
    Container container = Container::FromExtension;
    /// Include the scenes' nodes and meshes (false: only the nodes hoses attach to, without
    /// meshes, keeping their place in the hierarchy).
    bool includeSceneMeshes = true;
    /// Keep scene nodes that carry nothing (no mesh, no kept child, no hose attached). Off:
    /// they are left out (the validator reports empty nodes); node paths of kept nodes are
    /// unchanged.
    bool keepEmptyNodes = false;
    /// Write the hoses' TEXCOORD_0 (u around the profile, v = metres of rest length along the
    /// axis). Off by default: without a texture in the material the validator reports them as
    /// unused; turn on when artists will texture the hoses.
    bool writeTextureCoordinates = false;
    /// Joints of attached segments are children of their scene node (moving the node in any
    /// viewer carries them), and the free joints hang under the deepest common ancestor of the
    /// attachment nodes. Off: every joint of a hose hangs under its own "<id> joints" node at
    /// the root, so each hose has joints with a common root of its own (Blender then makes one
    /// armature per hose) but moving a scene node in a plain viewer leaves the hose behind;
    /// the descriptor still names the attachment nodes for a runtime.
    bool jointsUnderAttachedNodes = true;
    /// Export static hoses (every axis point fixed, all to one scene node or all to the world)
    /// as plain meshes; the descriptor marks them "static". Off: every hose is skinned.
    bool plainMeshesForStaticHoses = true;
    /// Scene nodes flagged as colliders (descriptor "colliders", glTF node indices): these nodes
    /// and their meshes are exported even when includeSceneMeshes is off, since a runtime
    /// builds its colliders from them. Each must have a mesh with triangles (InvalidArgument).
    std::vector<NodeRef> colliders;
    /// Moving parts (descriptor "motions"): each motion's node is exported (even without a
    /// mesh) and the descriptor names its glTF node; `motion.node` is ignored (InvalidArgument
    /// when the scene node does not exist).
    struct Motion
    {
        NodeRef node;
        rig::RigMotion motion;
    };
    std::vector<Motion> motions;
    /// Sockets (descriptor "sockets"): each socket's node is exported (even without a mesh);
    /// `socket.position` and `socket.axis` are in the node's rigid world frame (axis need not be
    /// unit); the descriptor gets the glTF node, its name, the unit axis and the world position
    /// and axis (InvalidArgument when the scene node does not exist; scene −1: world).
    struct Socket
    {
        NodeRef node;
        rig::RigSocket socket;
    };
    std::vector<Socket> sockets;
    /// Plug tags of hose ends (descriptor "plugs"), by ExportHose::id; "" (or a hose not
    /// listed): that end has none.
    struct Plugs
    {
        std::string start; ///< the end at the first axis point
        std::string end;   ///< the end at the last axis point
    };
    std::map<std::string, Plugs> plugs;
    /// Also write <name>.hoses.json beside the glTF.
    bool writeSidecarDescriptor = true;
    /// Called with the fraction done (0 … 1, non-decreasing) from the calling thread. Return
    /// false to cancel: the export then throws formats::Cancelled and writes nothing.
    std::function<bool(double fraction)> progress;
    /// asset.generator and the descriptor's generator.
    std::string generator = "ChainTube exporter";
};

/// One hose to export.
struct ExportHose
{
    std::string id;
    std::string name;
    Hose hose;                          ///< current shape, attachments already fixed
    std::vector<NodeRef> attachedNodes; ///< one per hose.attachments(), same order
    std::array<double, 4> baseColour{0.2, 0.2, 0.2, 1.0}; ///< linear RGBA [0, 1]
    double roughness = 0.5;                               ///< [0, 1]
};

/// What an export wrote.
struct ExportReport
{
    std::filesystem::path gltfFile;
    std::filesystem::path binFile;        ///< empty for GLB
    std::filesystem::path descriptorFile; ///< empty when not written
    int hoseCount = 0;
    int jointCount = 0;
    int sceneNodeCount = 0; ///< glTF nodes that came from the scenes
    std::size_t bytesWritten = 0;
    double seconds = 0.0;
    std::vector<std::string> warnings; ///< overstretch, bend below minimum, self-intersection
    rig::HoseRigDescriptor descriptor; ///< as embedded
};

/// Exports scenes + hoses to `output` (.glb or .gltf). Throws InvalidArgument for inconsistent
/// input (attachedNodes not matching a hose's attachments, node out of range, a scene node
/// under which a joint cannot be expressed as TRS because of shear), formats::FileError when a
/// file cannot be written (nothing is left behind), formats::Cancelled.
ExportReport exportRig(const std::vector<const formats::ImportedScene*>& scenes,
                       const std::vector<ExportHose>& hoses, const std::string& rootName,
                       const std::filesystem::path& output, const ExportOptions& options = {});

/// The editor's and the CLI's entry point: loads nothing, imports the project's scenes
/// (formats::importProjectScenes with `roots`), builds its hoses (formats::buildHoses) and
/// exports them with colours/roughness from the project. `output` empty: the project's export
/// settings (path, format) or <project name>.glb next to the project file. Progress covers
/// import (first 55 %), building the hoses (to 60 %, once per hose: gravity hoses settle there)
/// and export; cancelling (progress returns false) throws formats::Cancelled, nothing written.
/// Throws what importProjectScenes, buildHoses and exportRig throw.
ExportReport exportProject(const formats::Project& project,
                           const std::filesystem::path& projectFile, std::filesystem::path output,
                           const formats::NamedRoots& roots, const ExportOptions& options = {});

/// exportProject() for the project file: loadProject(projectFile, roots) first.
ExportReport exportProjectFile(const std::filesystem::path& projectFile,
                               const std::filesystem::path& output,
                               const formats::NamedRoots& roots, const ExportOptions& options = {});

/// Warnings the library's measures give for a hose (overstretch, joints bending below the
/// minimum bend radius, ring self-intersection), each prefixed with `label`.
std::vector<std::string> hoseWarnings(const Hose& hose, const std::string& label);

} // namespace chaintube::exporting
