// Internal: reading a .glb/.gltf file's JSON text and binary chunk (shared by the runtime's
// loader and the exporter's validate).
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace chaintube::rig::detail {

/// The whole file. Throws chaintube::Error "<file>: cannot be read …".
std::string readFileBytes(const std::filesystem::path& file);

struct GltfContainer
{
    std::string json;     ///< the glTF JSON text
    std::string binChunk; ///< GLB only: the BIN chunk (buffer 0), empty if none
};

/// Splits a GLB into its JSON and BIN chunks (checking the header, version 2, chunk types and
/// lengths), or returns a .gltf's bytes as the JSON. Throws chaintube::Error naming the file.
GltfContainer splitGltf(const std::filesystem::path& file, const std::string& bytes);

/// A glTF's JSON and its buffers, read without tinygltf's loader (Debian's libtinygltf.so
/// disagrees with its header about the TinyGLTF class layout: loading corrupts the heap).
struct GltfFile
{
    nlohmann::json json;
    std::vector<std::string> buffers;
};

/// Reads the JSON and every buffer: buffer 0 of a GLB from its BIN chunk, the others (and a
/// .gltf's) from files beside the glTF only (a uri leaving its folder, an absolute path or a
/// data URI is refused). Throws chaintube::Error naming the file and the pointer.
GltfFile readGltf(const std::filesystem::path& file);

/// Float accessor `index` (tightly packed or strided), bounds-checked without overflow.
/// Throws chaintube::Error prefixed with `where`.
std::vector<float> floatsOf(const GltfFile& gltf, int index, const std::string& where);

/// Index accessor `index` (unsigned byte, short or int scalars), bounds-checked. Throws
/// chaintube::Error prefixed with `where`.
std::vector<std::uint32_t> indicesOf(const GltfFile& gltf, int index, const std::string& where);

} // namespace chaintube::rig::detail
