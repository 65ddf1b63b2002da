// Internal: reading a .glb/.gltf file's JSON text and binary chunk (shared by the runtime's
// loader and the exporter's validate).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace chaintube::rig::detail {

/// The whole file. Throws rig::UnreadableFile "<file>: cannot be read …".
std::string readFileBytes(const std::filesystem::path& file);

struct GltfContainer
{
    std::string json;     ///< the glTF JSON text
    std::string binChunk; ///< GLB only: the BIN chunk (buffer 0), empty if none
};

/// Splits a GLB into its JSON and BIN chunks (checking the header, version 2, chunk types and
/// lengths), or returns a .gltf's bytes as the JSON. Throws chaintube::Error prefixed with
/// `name` (the file, or what names bytes held in memory).
GltfContainer splitGltf(const std::string& name, std::string_view bytes);

/// A glTF's JSON and its buffers, read without tinygltf's loader (Debian's libtinygltf.so
/// disagrees with its header about the TinyGLTF class layout: loading corrupts the heap).
struct GltfFile
{
    nlohmann::json json;
    std::vector<std::string> buffers;
};

/// The bytes of /buffers/`index`, whose uri is `uri`; `where` is "<name>: /buffers/<index>"
/// for messages.
using ExternalBuffer =
    std::function<std::string(size_t index, const std::string& uri, const std::string& where)>;

/// Every buffer of a parsed glTF, in /buffers order: one without a uri is the GLB's BIN chunk
/// (buffer 0 only), one with a uri comes from `external`. Checks each against its byteLength.
/// Throws chaintube::Error prefixed with `name` and the pointer.
std::vector<std::string> gatherBuffers(const nlohmann::json& gltf, const std::string& binChunk,
                                       const std::string& name, const ExternalBuffer& external);

/// A buffer file named by a uri relative to the glTF file `file`: percent-decoded, and only a
/// file beside the glTF (a uri leaving its folder, an absolute path or a data URI is refused).
std::string readBufferBeside(const std::filesystem::path& file, const std::string& uri,
                             const std::string& where);

/// Reads the JSON and every buffer: buffer 0 of a GLB from its BIN chunk, the others (and a
/// .gltf's) from files beside the glTF only (readBufferBeside). Throws chaintube::Error naming
/// the file and the pointer.
GltfFile readGltf(const std::filesystem::path& file);

/// Float accessor `index` (tightly packed or strided), bounds-checked without overflow.
/// Throws chaintube::Error prefixed with `where`.
std::vector<float> floatsOf(const GltfFile& gltf, int index, const std::string& where);

/// Index accessor `index` (unsigned byte, short or int scalars), bounds-checked. Throws
/// chaintube::Error prefixed with `where`.
std::vector<std::uint32_t> indicesOf(const GltfFile& gltf, int index, const std::string& where);

} // namespace chaintube::rig::detail
