#include "gltf_container.h"

#include "chaintube/export/runtime.h"
#include "chaintube/formats/paths.h"
#include "chaintube/types.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>

namespace chaintube::rig::detail {

namespace {

std::uint32_t readU32(std::string_view bytes, size_t at)
{
    std::uint32_t value = 0;
    std::memcpy(&value, bytes.data() + at, 4);
    return value; // GLB is little-endian, as every platform we build for
}

using Json = nlohmann::json;

/// A buffer URI is an RFC 3986 relative reference: "rig%20v2.bin" names the file "rig v2.bin".
/// Decodes %XX escapes; a '%' without two hex digits after it, or an escaped NUL byte, is
/// refused (`where` names the buffer).
std::string percentDecoded(const std::string& uri, const std::string& where)
{
    const auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    std::string decoded;
    decoded.reserve(uri.size());
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] != '%') {
            decoded += uri[i];
            continue;
        }
        const int high = i + 2 < uri.size() ? hex(uri[i + 1]) : -1;
        const int low = i + 2 < uri.size() ? hex(uri[i + 2]) : -1;
        if (high < 0 || low < 0)
            throw Error(where + "/uri: \"" + uri + "\": malformed percent-encoding at byte " +
                        std::to_string(i) + " (expected % and two hex digits)");
        if (high == 0 && low == 0)
            throw Error(where + "/uri: \"" + uri + "\": %00 (a NUL byte) is not a file name");
        decoded += static_cast<char>(high * 16 + low);
        i += 2;
    }
    return decoded;
}

} // namespace

std::string readFileBytes(const std::filesystem::path& file)
{
    std::ifstream stream(file, std::ios::binary);
    if (!stream)
        throw UnreadableFile(file.string() + ": cannot be read (missing or no permission)");
    return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

GltfContainer splitGltf(const std::string& name, std::string_view bytes)
{
    GltfContainer container;
    if (bytes.size() < 4 || bytes.compare(0, 4, "glTF") != 0) {
        container.json = bytes;
        return container;
    }
    if (bytes.size() < 20) throw Error(name + ": truncated GLB header");
    if (readU32(bytes, 4) != 2)
        throw Error(name + ": GLB container version " + std::to_string(readU32(bytes, 4)) +
                    ", expected 2");
    if (readU32(bytes, 8) != bytes.size())
        throw Error(name + ": GLB header length does not match the file size");
    const size_t jsonLength = readU32(bytes, 12);
    if (readU32(bytes, 16) != 0x4E4F534Au || 20 + jsonLength > bytes.size())
        throw Error(name + ": GLB's first chunk is not a complete JSON chunk");
    container.json = bytes.substr(20, jsonLength);
    const size_t binAt = 20 + jsonLength;
    if (binAt + 8 <= bytes.size()) {
        const size_t binLength = readU32(bytes, binAt);
        if (readU32(bytes, binAt + 4) != 0x004E4942u || binAt + 8 + binLength > bytes.size())
            throw Error(name + ": GLB's second chunk is not a complete BIN chunk");
        container.binChunk = bytes.substr(binAt + 8, binLength);
    }
    return container;
}

std::vector<std::string> gatherBuffers(const Json& gltf, const std::string& binChunk,
                                       const std::string& name, const ExternalBuffer& external)
{
    std::vector<std::string> gathered;
    const Json& buffers = gltf.value("buffers", Json::array());
    for (size_t b = 0; b < buffers.size(); ++b) {
        const std::string where = name + ": /buffers/" + std::to_string(b);
        std::string data;
        if (!buffers[b].contains("uri")) {
            if (b != 0) throw Error(where + ": only buffer 0 may omit its uri (the GLB BIN chunk)");
            data = binChunk;
        } else {
            if (!buffers[b]["uri"].is_string()) throw Error(where + "/uri: expected a string");
            data = external(b, buffers[b]["uri"].get<std::string>(), where);
        }
        if (data.size() < buffers[b].value("byteLength", std::size_t{0}))
            throw Error(where + "/byteLength: the buffer has only " + std::to_string(data.size()) +
                        " bytes");
        gathered.push_back(std::move(data));
    }
    return gathered;
}

std::string readBufferBeside(const std::filesystem::path& file, const std::string& uri,
                             const std::string& where)
{
    if (uri.rfind("data:", 0) == 0) throw Error(where + "/uri: data URIs are not read by validate");
    // A buffer is a file beside the glTF: never read what a hostile file points at
    // elsewhere ("../../etc/passwd", "/dev/zero", a link out of the folder).
    // The check is on the decoded name: "%2E%2E/x" is "../x".
    const std::string name = percentDecoded(uri, where);
    const std::filesystem::path folder = std::filesystem::absolute(file).parent_path();
    const std::filesystem::path bufferFile = folder / name;
    if (name.empty() || std::filesystem::path(name).is_absolute() ||
        !formats::isInsideFolder(bufferFile, folder))
        throw Error(where + "/uri: \"" + uri + "\"" +
                    (name != uri ? " (decoded \"" + name + "\")" : std::string()) +
                    " is outside the glTF's folder (only files beside it are read)");
    return readFileBytes(bufferFile);
}

GltfFile readGltf(const std::filesystem::path& file)
{
    GltfFile gltf;
    const GltfContainer container = splitGltf(file.string(), readFileBytes(file));
    try {
        gltf.json = Json::parse(container.json);
    } catch (const Json::exception& error) {
        throw Error(file.string() + ": malformed glTF JSON: " + error.what());
    }
    gltf.buffers = gatherBuffers(gltf.json, container.binChunk, file.string(),
                                 [&](size_t, const std::string& uri, const std::string& where) {
                                     return readBufferBeside(file, uri, where);
                                 });
    return gltf;
}

std::vector<float> floatsOf(const GltfFile& gltf, int index, const std::string& where)
{
    const Json& accessor = gltf.json.at("accessors").at(static_cast<size_t>(index));
    if (accessor.value("componentType", 0) != 5126)
        throw Error(where + ": expected a float accessor");
    const std::map<std::string, size_t> componentsOf{
        {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT4", 16}};
    const size_t components = componentsOf.at(accessor.value("type", "SCALAR"));
    const size_t count = accessor.value("count", std::size_t{0});
    const Json& view = gltf.json.at("bufferViews").at(accessor.at("bufferView").get<size_t>());
    const std::string& buffer = gltf.buffers.at(view.value("buffer", std::size_t{0}));
    const size_t elementBytes = components * 4;
    const size_t stride = view.value("byteStride", elementBytes);
    const size_t viewOffset = view.value("byteOffset", std::size_t{0});
    const size_t accessorOffset = accessor.value("byteOffset", std::size_t{0});
    if (stride < elementBytes)
        throw Error(where + ": accessor " + std::to_string(index) + ": byteStride " +
                    std::to_string(stride) + " is smaller than an element");
    // Checked without overflow: a hostile count or offset must not wrap around the test.
    const size_t size = buffer.size();
    const bool fits =
        viewOffset <= size && accessorOffset <= size - viewOffset &&
        (count == 0 || (elementBytes <= size - viewOffset - accessorOffset &&
                        count - 1 <= (size - viewOffset - accessorOffset - elementBytes) / stride));
    if (!fits)
        throw Error(where + ": accessor " + std::to_string(index) + " reaches beyond its buffer");
    const size_t start = viewOffset + accessorOffset;
    std::vector<float> values(count * components);
    for (size_t i = 0; i < count; ++i)
        std::memcpy(&values[i * components], buffer.data() + start + i * stride, components * 4);
    return values;
}

std::vector<std::uint32_t> indicesOf(const GltfFile& gltf, int index, const std::string& where)
{
    const Json& accessor = gltf.json.at("accessors").at(static_cast<size_t>(index));
    const int type = accessor.value("componentType", 0);
    const size_t bytes = type == 5121 ? 1 : type == 5123 ? 2 : type == 5125 ? 4 : 0;
    if (bytes == 0 || accessor.value("type", "") != "SCALAR")
        throw Error(where + ": accessor " + std::to_string(index) +
                    ": expected unsigned byte, short or int scalars");
    const size_t count = accessor.value("count", std::size_t{0});
    const Json& view = gltf.json.at("bufferViews").at(accessor.at("bufferView").get<size_t>());
    const std::string& buffer = gltf.buffers.at(view.value("buffer", std::size_t{0}));
    const size_t stride = view.value("byteStride", bytes);
    const size_t viewOffset = view.value("byteOffset", std::size_t{0});
    const size_t accessorOffset = accessor.value("byteOffset", std::size_t{0});
    const size_t size = buffer.size();
    const bool fits =
        stride >= bytes && viewOffset <= size && accessorOffset <= size - viewOffset &&
        (count == 0 || (bytes <= size - viewOffset - accessorOffset &&
                        count - 1 <= (size - viewOffset - accessorOffset - bytes) / stride));
    if (!fits)
        throw Error(where + ": accessor " + std::to_string(index) + " reaches beyond its buffer");
    const size_t start = viewOffset + accessorOffset;
    std::vector<std::uint32_t> values(count);
    for (size_t i = 0; i < count; ++i) {
        const char* at = buffer.data() + start + i * stride;
        if (bytes == 1) values[i] = static_cast<unsigned char>(*at);
        if (bytes == 2) {
            std::uint16_t v = 0;
            std::memcpy(&v, at, 2);
            values[i] = v;
        }
        if (bytes == 4) std::memcpy(&values[i], at, 4);
    }
    return values;
}

} // namespace chaintube::rig::detail
