#include "gltf_container.h"

#include "chaintube/types.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>

namespace chaintube::rig::detail {

namespace {

std::uint32_t readU32(const std::string& bytes, size_t at)
{
    std::uint32_t value = 0;
    std::memcpy(&value, bytes.data() + at, 4);
    return value; // GLB is little-endian, as every platform we build for
}

} // namespace

std::string readFileBytes(const std::filesystem::path& file)
{
    std::ifstream stream(file, std::ios::binary);
    if (!stream) throw Error(file.string() + ": cannot be read (missing or no permission)");
    return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

GltfContainer splitGltf(const std::filesystem::path& file, const std::string& bytes)
{
    GltfContainer container;
    if (bytes.size() < 4 || bytes.compare(0, 4, "glTF") != 0) {
        container.json = bytes;
        return container;
    }
    if (bytes.size() < 20) throw Error(file.string() + ": truncated GLB header");
    if (readU32(bytes, 4) != 2)
        throw Error(file.string() + ": GLB container version " + std::to_string(readU32(bytes, 4)) +
                    ", expected 2");
    if (readU32(bytes, 8) != bytes.size())
        throw Error(file.string() + ": GLB header length does not match the file size");
    const size_t jsonLength = readU32(bytes, 12);
    if (readU32(bytes, 16) != 0x4E4F534Au || 20 + jsonLength > bytes.size())
        throw Error(file.string() + ": GLB's first chunk is not a complete JSON chunk");
    container.json = bytes.substr(20, jsonLength);
    const size_t binAt = 20 + jsonLength;
    if (binAt + 8 <= bytes.size()) {
        const size_t binLength = readU32(bytes, binAt);
        if (readU32(bytes, binAt + 4) != 0x004E4942u || binAt + 8 + binLength > bytes.size())
            throw Error(file.string() + ": GLB's second chunk is not a complete BIN chunk");
        container.binChunk = bytes.substr(binAt + 8, binLength);
    }
    return container;
}

} // namespace chaintube::rig::detail
