// Internal to chaintube_export: building a glTF model with tinygltf. Buffer 0 and the accessors
// that view it, node transforms, scene meshes, and the two parts of an export that live in files
// of their own: each hose's mesh, skin and joints (hose_skin.cpp) and writing the files
// (rig_files.cpp). exportRig (gltf_export.cpp) puts them together.
#pragma once

#include "../runtime/transform_math.h"
#include "chaintube/export/gltf_export.h"
#include "chaintube/export/rig_descriptor.h"
#include "chaintube/formats/scene.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <tiny_gltf.h>
#include <vector>

namespace chaintube::exporting::detail {

using rig::detail::Affine;

constexpr int kArrayBuffer = TINYGLTF_TARGET_ARRAY_BUFFER;
constexpr int kElementArrayBuffer = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;

Affine affineOf(const formats::Mat4& m);

/// Accumulates buffer 0 and the accessors that view it.
class BufferWriter
{
public:
    explicit BufferWriter(tinygltf::Model& model) : m_model(model) {}

    int view(const void* data, size_t bytes, int target)
    {
        while (m_bytes.size() % 4)
            m_bytes.push_back(0);
        tinygltf::BufferView view;
        view.buffer = 0;
        view.byteOffset = m_bytes.size();
        view.byteLength = bytes;
        view.target = target;
        const auto* begin = static_cast<const unsigned char*>(data);
        m_bytes.insert(m_bytes.end(), begin, begin + bytes);
        m_model.bufferViews.push_back(view);
        return static_cast<int>(m_model.bufferViews.size()) - 1;
    }

    int accessor(int view, int componentType, size_t count, int type, std::vector<double> min = {},
                 std::vector<double> max = {})
    {
        tinygltf::Accessor accessor;
        accessor.bufferView = view;
        accessor.componentType = componentType;
        accessor.count = count;
        accessor.type = type;
        accessor.minValues = std::move(min);
        accessor.maxValues = std::move(max);
        m_model.accessors.push_back(accessor);
        return static_cast<int>(m_model.accessors.size()) - 1;
    }

    int vec3Floats(const std::vector<float>& values, bool withBounds)
    {
        std::vector<double> low, high;
        if (withBounds) {
            low.assign(3, std::numeric_limits<double>::infinity());
            high.assign(3, -std::numeric_limits<double>::infinity());
            for (size_t i = 0; i < values.size(); ++i) {
                low[i % 3] = std::min(low[i % 3], static_cast<double>(values[i]));
                high[i % 3] = std::max(high[i % 3], static_cast<double>(values[i]));
            }
        }
        const int v = view(values.data(), values.size() * sizeof(float), kArrayBuffer);
        return accessor(v, TINYGLTF_COMPONENT_TYPE_FLOAT, values.size() / 3, TINYGLTF_TYPE_VEC3,
                        low, high);
    }

    int indices(const std::vector<std::uint32_t>& values, size_t vertexCount)
    {
        if (vertexCount <= 65535) {
            std::vector<std::uint16_t> narrow(values.begin(), values.end());
            const int v = view(narrow.data(), narrow.size() * 2, kElementArrayBuffer);
            return accessor(v, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, values.size(),
                            TINYGLTF_TYPE_SCALAR);
        }
        const int v = view(values.data(), values.size() * 4, kElementArrayBuffer);
        return accessor(v, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, values.size(),
                        TINYGLTF_TYPE_SCALAR);
    }

    std::vector<unsigned char>& bytes() { return m_bytes; }

private:
    tinygltf::Model& m_model;
    std::vector<unsigned char> m_bytes;
};

/// Sets a node's transform as TRS when the matrix is one (always for joints), else `matrix`.
/// Throws InvalidArgument naming `what` when a matrix is not allowed and the transform has shear.
void setTransform(tinygltf::Node& node, const Affine& local, bool allowMatrix,
                  const std::string& what);

/// Unit normals (a zero or non-finite normal gets the triangle-free default +Y: the validator
/// rejects non-unit normals, and CAD tessellations sometimes carry degenerate ones).
std::vector<float> unitNormals(const std::vector<float>& normals);

struct SceneMeshAccessors
{
    bool empty = true;
    int position = -1, normal = -1, indices = -1;
};

/// Writes a scene mesh's positions, normals and triangles (degenerate or broken triangles left
/// out) into the buffer. empty when nothing is left to draw.
SceneMeshAccessors writeSceneMesh(BufferWriter& buffer, const formats::SceneMesh& mesh);

/// Calls options.progress; throws formats::Cancelled when it returns false.
void reportProgress(const ExportOptions& options, double fraction,
                    const std::filesystem::path& output);

/// Per scene (index of the scenes passed to exportRig), the glTF node of each scene node, −1
/// for a node left out.
using GltfNodeOf = std::vector<std::vector<int>>;

/// Adds one hose to the model (hose_skin.cpp): its descriptor entry; for a skinned hose the
/// "<id> joints" node, one joint per axis point under the node it follows, the skin with its
/// inverse bind matrices and the skinned mesh node at the scene root (`scene`); for a static hose
/// a plain mesh under its node. Warnings and joints are added to `report`. Throws
/// InvalidArgument when a joint's parent has shear.
rig::RigHose writeHose(tinygltf::Model& model, BufferWriter& buffer, tinygltf::Scene& scene,
                       const std::vector<const formats::ImportedScene*>& scenes,
                       const GltfNodeOf& gltfNodeOf, const ExportHose& input,
                       const ExportOptions& options, ExportReport& report);

/// Serialises the model with the descriptor as its CHAINTUBE_hose_rig extension and writes the
/// glTF (GLB or .gltf + .bin) and, if asked, the sidecar <name>.hoses.json (rig_files.cpp):
/// every file first complete as <file>.partial, then all renamed, the glTF last. Sets the
/// report's file names and bytesWritten. Throws formats::FileError (nothing of a previous
/// export changed unless a rename failed midway), formats::Cancelled.
void writeRigFiles(tinygltf::Model& model, const rig::HoseRigDescriptor& descriptor,
                   Container container, const std::filesystem::path& output,
                   const ExportOptions& options, ExportReport& report);

} // namespace chaintube::exporting::detail
