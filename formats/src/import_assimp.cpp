// Scene import through assimp (every format except STEP).
#include "import_internal.h"

#include <assimp/Importer.hpp>
#include <assimp/ProgressHandler.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cctype>
#include <cmath>
#include <cstring>
#include <utility>

namespace chaintube::formats::detail {

namespace {

/// Forwards assimp's progress to the caller; assimp ignores our "cancel" answer, so the
/// request is also remembered and honoured when ReadFile returns.
class ProgressForwarder : public Assimp::ProgressHandler
{
public:
    explicit ProgressForwarder(ProgressStage& stage) : m_stage(stage) {}
    bool Update(float percentage) override
    {
        // Reading the file is the first 70 % of the stage, post-processing the rest.
        if (percentage < 0.0f) return !m_stage.cancelRequested();
        return m_stage.reportNoThrow(0.7 * static_cast<double>(percentage));
    }
    void UpdatePostProcess(int currentStep, int numberOfSteps) override
    {
        const double fraction =
            numberOfSteps > 0 ? static_cast<double>(currentStep) / numberOfSteps : 1.0;
        m_stage.reportNoThrow(0.7 + 0.1 * fraction);
    }

private:
    ProgressStage& m_stage;
};

Mat4 toMat4(const aiMatrix4x4& m)
{
    Mat4 result;
    result << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2,
        m.d3, m.d4;
    return result;
}

bool metadataNumber(const aiMetadata* metadata, const char* key, double& value)
{
    if (!metadata) return false;
    for (unsigned i = 0; i < metadata->mNumProperties; ++i) {
        if (std::strcmp(metadata->mKeys[i].C_Str(), key) != 0) continue;
        const aiMetadataEntry& entry = metadata->mValues[i];
        switch (entry.mType) {
        case AI_INT32:
            value = *static_cast<const int32_t*>(entry.mData);
            return true;
        case AI_UINT64:
            value = static_cast<double>(*static_cast<const uint64_t*>(entry.mData));
            return true;
        case AI_FLOAT:
            value = *static_cast<const float*>(entry.mData);
            return true;
        case AI_DOUBLE:
            value = *static_cast<const double*>(entry.mData);
            return true;
        default:
            return false;
        }
    }
    return false;
}

bool isAssimpGltfIndexName(const std::string& name)
{
    const std::string prefix = "nodes[";
    if (name.size() < prefix.size() + 2 || name.compare(0, prefix.size(), prefix) != 0 ||
        name.back() != ']')
        return false;
    for (size_t i = prefix.size(); i + 1 < name.size(); ++i)
        if (!std::isdigit(static_cast<unsigned char>(name[i]))) return false;
    return true;
}

} // namespace

std::string assimpFormatName(const std::string& extension)
{
    if (extension == ".gltf" || extension == ".glb") return "glTF";
    if (extension == ".dae") return "COLLADA";
    std::string name = extension.substr(1);
    for (char& c : name)
        c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return name;
}

namespace {

/// What each format says about units and up axis (before looking at the file's metadata).
void conventionalUnits(const std::string& extension, SourceUnits& units)
{
    if (extension == ".gltf" || extension == ".glb") {
        // glTF 2.0 §3.4: metres, +Y up.
        units = {1.0, "metre", UnitSource::FormatConvention, UpAxis::PositiveY,
                 UnitSource::FormatConvention};
    } else if (extension == ".ifc" || extension == ".dae") {
        // assimp's IFC and COLLADA readers apply the file's unit and up axis themselves (into
        // vertices / the root transform), so what they hand over is metres, +Y up.
        units = {1.0, "metre (converted by the reader from the file's unit)",
                 UnitSource::FileHeader, UpAxis::PositiveY, UnitSource::FileHeader};
    } else if (extension == ".3mf") {
        // 3MF core spec: millimetres unless the model says otherwise; +Z up. assimp 5.2 does
        // not expose the model's unit attribute.
        units = {0.001, "millimetre", UnitSource::FormatConvention, UpAxis::PositiveZ,
                 UnitSource::FormatConvention};
    } else if (extension == ".amf") {
        units = {0.001, "millimetre", UnitSource::FormatConvention, UpAxis::PositiveZ,
                 UnitSource::FormatConvention};
    } else {
        units = {1.0, "metre", UnitSource::Assumed, UpAxis::PositiveY, UnitSource::Assumed};
    }
}

} // namespace

ReaderResult importWithAssimp(const std::filesystem::path& file, const std::string& extension,
                              const ImportOptions& options, ProgressStage& progress)
{
    (void)options;
    Assimp::Importer importer;
    // No helper nodes for FBX pivots: the node tree stays the author's.
    importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
    // COLLADA: the node's name attribute (what the author typed), not its XML id.
    importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_USE_COLLADA_NAMES, true);
    // Keep lines/points out of the triangle meshes.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    auto* forwarder = new ProgressForwarder(progress); // the importer owns it until reset
    importer.SetProgressHandler(forwarder);

    // Deliberately no aiProcess_PreTransformVertices / OptimizeGraph / OptimizeMeshes: they
    // collapse or merge nodes, and hoses attach to nodes by name.
    const unsigned flags = aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_GenNormals |
                           aiProcess_ValidateDataStructure;
    const aiScene* source = importer.ReadFile(file.string(), flags);
    // Setting nullptr hands the handler back to us (assimp then installs its default one); the
    // importer deletes it only if it still holds it (LeakSanitizer found it leaked per import).
    importer.SetProgressHandler(nullptr);
    delete forwarder;
    progress.throwIfCancelRequested();
    if (!source) {
        std::string reason = importer.GetErrorString();
        if (reason.empty()) reason = "the reader gave no reason";
        throw FileError(file, "cannot read " + assimpFormatName(extension) + " file: " + reason);
    }
    if ((source->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !source->mRootNode)
        throw FileError(file, "the " + assimpFormatName(extension) +
                                  " file is incomplete (no scene graph or no geometry)");

    ReaderResult result;
    ImportedScene& scene = result.scene;
    scene.format = assimpFormatName(extension);
    conventionalUnits(extension, scene.sourceUnits);

    // FBX: UnitScaleFactor is centimetres per file unit; UpAxis 0/1/2 = X/Y/Z.
    double unitScaleFactor = 0.0;
    if (extension == ".fbx" &&
        metadataNumber(source->mMetaData, "UnitScaleFactor", unitScaleFactor) &&
        std::isfinite(unitScaleFactor) && unitScaleFactor > 0.0) {
        scene.sourceUnits.metresPerUnit = unitScaleFactor * 0.01;
        scene.sourceUnits.unitName =
            unitScaleFactor == 1.0 ? "centimetre" : std::to_string(unitScaleFactor) + " cm";
        scene.sourceUnits.unitSource = UnitSource::FileHeader;
        double upAxis = 1.0;
        if (metadataNumber(source->mMetaData, "UpAxis", upAxis)) {
            scene.sourceUnits.upAxis = upAxis == 2.0 ? UpAxis::PositiveZ : UpAxis::PositiveY;
            scene.sourceUnits.upAxisSource = UnitSource::FileHeader;
        }
    }

    // --- meshes -------------------------------------------------------------------------------
    std::size_t totalFaces = 0;
    for (unsigned m = 0; m < source->mNumMeshes; ++m)
        totalFaces += source->mMeshes[m]->mNumFaces;
    std::size_t facesDone = 0;
    std::vector<int> meshMap(source->mNumMeshes, -1); // assimp mesh → our mesh (−1: dropped)
    for (unsigned m = 0; m < source->mNumMeshes; ++m) {
        const aiMesh* in = source->mMeshes[m];
        if (!(in->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        SceneMesh out;
        out.name = in->mName.C_Str();
        out.positions.resize(3 * size_t(in->mNumVertices));
        out.normals.resize(3 * size_t(in->mNumVertices));
        for (unsigned v = 0; v < in->mNumVertices; ++v) {
            const aiVector3D& p = in->mVertices[v];
            out.positions[3 * v] = p.x;
            out.positions[3 * v + 1] = p.y;
            out.positions[3 * v + 2] = p.z;
            aiVector3D n = in->mNormals ? in->mNormals[v] : aiVector3D(0, 0, 0);
            if (!(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z)) ||
                n.SquareLength() == 0.0f)
                n = aiVector3D(0, 1, 0); // degenerate triangle: any unit normal will do
            n.Normalize();
            out.normals[3 * v] = n.x;
            out.normals[3 * v + 1] = n.y;
            out.normals[3 * v + 2] = n.z;
        }
        out.indices.reserve(3 * size_t(in->mNumFaces));
        for (unsigned f = 0; f < in->mNumFaces; ++f) {
            const aiFace& face = in->mFaces[f];
            if (face.mNumIndices == 3)
                out.indices.insert(out.indices.end(), face.mIndices, face.mIndices + 3);
            if ((++facesDone & 0xFFFF) == 0)
                progress.report(0.8 + 0.2 * static_cast<double>(facesDone) / totalFaces);
        }
        meshMap[m] = static_cast<int>(scene.meshes.size());
        scene.meshes.push_back(std::move(out));
    }

    const bool isGltf = extension == ".gltf" || extension == ".glb";
    // --- nodes (depth first, parents before children) ----------------------------------------
    std::vector<std::pair<const aiNode*, int>> stack{{source->mRootNode, -1}};
    while (!stack.empty()) {
        auto [in, parent] = stack.back();
        stack.pop_back();
        const int index = static_cast<int>(scene.nodes.size());
        SceneNode node;
        node.name = in->mName.C_Str();
        // assimp names unnamed glTF nodes after their index ("nodes[12]"): that is not a name
        // the author gave, so let finaliseScene() generate a proper one.
        if (isGltf && isAssimpGltfIndexName(node.name)) node.name.clear();
        // Likewise assimp's COLLADA reader for nodes with neither name nor id.
        if (node.name.rfind("$ColladaAutoName$", 0) == 0) node.name.clear();
        node.parent = parent;
        node.localTransform = toMat4(in->mTransformation);
        if (!node.localTransform.allFinite())
            throw FileError(file, "node '" + node.name + "' has a non-finite transform");
        for (unsigned k = 0; k < in->mNumMeshes; ++k) {
            const unsigned meshIndex = in->mMeshes[k];
            if (meshIndex < meshMap.size() && meshMap[meshIndex] >= 0)
                node.meshes.push_back(meshMap[meshIndex]);
        }
        scene.nodes.push_back(std::move(node));
        if (parent >= 0) scene.nodes[static_cast<size_t>(parent)].children.push_back(index);
        // Push in reverse so children are visited (and numbered) in file order.
        for (unsigned c = in->mNumChildren; c-- > 0;)
            stack.push_back({in->mChildren[c], index});
    }
    result.metresPerReaderUnit = scene.sourceUnits.metresPerUnit;
    progress.report(1.0);
    return result;
}

} // namespace chaintube::formats::detail
