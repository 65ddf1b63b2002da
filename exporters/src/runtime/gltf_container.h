// Internal: reading a .glb/.gltf file's JSON text and binary chunk (shared by the runtime's
// loader and the exporter's validate).
#pragma once

#include <filesystem>
#include <string>

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

} // namespace chaintube::rig::detail
