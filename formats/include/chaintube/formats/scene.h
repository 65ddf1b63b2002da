// ChainTube formats — the plain scene model that every CAD importer produces.
#pragma once

#include "chaintube/types.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace chaintube::formats {

/// 4×4 affine transform (column vectors: world = M · local). May contain scale and shear, as
/// CAD node transforms do; use chaintube::rigidPart() (types.h) when a Frame is needed.
using Mat4 = Eigen::Matrix<double, 4, 4, Eigen::DontAlign>;

/// A triangle mesh in its node's local frame, in metres.
struct SceneMesh
{
    std::string name;
    std::vector<float> positions;       ///< 3 per vertex, metres, node-local
    std::vector<float> normals;         ///< 3 per vertex, unit length (same count as positions)
    std::vector<std::uint32_t> indices; ///< 3 per triangle, counter-clockwise = front
    std::size_t vertexCount() const { return positions.size() / 3; }
    std::size_t triangleCount() const { return indices.size() / 3; }
};

/// One node of the scene graph.
struct SceneNode
{
    /// The name the file gave, or a generated one when the file had none (generatedName):
    /// the name of the node's first mesh if that has one (as Blender does for glTF; a mesh
    /// split by the reader into "base-0", "base-1", … gives "base"), else
    /// "node" followed by the child indices from the root, e.g. "node_2_0" is the first child
    /// of the root's third child. Both are stable for the same file. (assimp's placeholder
    /// names for unnamed glTF nodes, "nodes[12]", count as no name.)
    std::string name;
    bool generatedName = false;
    /// Unique path from the root: "/" + names joined by "/", e.g. "/root/engine/piston_1".
    /// '/' inside a name becomes '_'; a name already used by an earlier sibling gets "#2",
    /// "#3", … appended in the path (not in name), in file order. Hoses attach by this path.
    std::string path;
    int parent = -1;           ///< index into ImportedScene::nodes; −1 only for the root
    std::vector<int> children; ///< in file order
    Mat4 localTransform = Mat4::Identity(); ///< parent ← this node, metres
    std::vector<int> meshes; ///< indices into ImportedScene::meshes (shared instances ok)
};

/// Up axis of a source file.
enum class UpAxis { PositiveY, PositiveZ };

/// Where the source's unit / up axis came from.
enum class UnitSource {
    FileHeader,       ///< the file states it (FBX UnitScaleFactor, STEP/IFC unit entities)
    FormatConvention, ///< the format's specification fixes it (glTF: metres, +Y up)
    Assumed,          ///< the format does not say (OBJ, STL, PLY, 3DS): metres / +Y assumed
    UserOverride,     ///< ImportOptions said so
};

const char* toString(UnitSource source);
const char* toString(UpAxis axis);

/// What the importer found about the source's units and how it converted them.
struct SourceUnits
{
    double metresPerUnit = 1.0; ///< one source length unit in metres (0.001 for millimetres)
    std::string unitName = "metre";
    UnitSource unitSource = UnitSource::Assumed;
    UpAxis upAxis = UpAxis::PositiveY;
    UnitSource upAxisSource = UnitSource::Assumed;
};

/// An imported scene: node tree, meshes, all in metres with +Y up (glTF conventions).
///
/// Unit and axis conversion are baked in: mesh positions and node translations are scaled to
/// metres, and a +Z-up source gets a −90° rotation about X on the root node's transform.
/// nodes[0] is the root; a parent always comes before its children.
struct ImportedScene
{
    std::filesystem::path file;
    std::string format; ///< e.g. "glTF", "STEP", "IFC" (human-readable)
    std::vector<SceneNode> nodes;
    std::vector<SceneMesh> meshes;
    SourceUnits sourceUnits;

    /// Index of the node with this path ("/root/engine/piston_1"), or −1.
    int findNode(std::string_view path) const;
    /// Indices of the nodes whose name (not path) equals name, in node order.
    std::vector<int> findNodesByName(std::string_view name) const;
    /// world ← node transform (product of local transforms from the root), metres.
    Mat4 worldTransform(int node) const;
    /// Rigid part of worldTransform(node) (chaintube::rigidPart: scale and shear removed by
    /// polar decomposition): the frame hose attachments use.
    Frame worldFrame(int node) const;
    /// Sum over nodes of the triangles of their meshes (instances counted each time).
    std::size_t instancedTriangleCount() const;
    /// Sum of triangles of the distinct meshes.
    std::size_t meshTriangleCount() const;
};

} // namespace chaintube::formats
