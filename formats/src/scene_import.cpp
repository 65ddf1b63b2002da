#include "chaintube/formats/scene_import.h"

#include "import_internal.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

namespace chaintube::formats {

namespace {

std::string lowerCaseExtension(const std::filesystem::path& file)
{
    std::string extension = file.extension().string();
    for (char& c : extension)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return extension;
}

bool isStep(const std::string& extension)
{
    return extension == ".stp" || extension == ".step";
}

/// Missing, not a regular file, unreadable, empty: the reasons we can give before any parser.
void checkReadableFile(const std::filesystem::path& file)
{
    std::error_code error;
    const auto status = std::filesystem::status(file, error);
    if (!std::filesystem::exists(status)) throw FileError(file, "no such file");
    if (std::filesystem::is_directory(status))
        throw FileError(file, "is a directory, not a scene file");
    if (!std::filesystem::is_regular_file(status)) throw FileError(file, "not a regular file");
    std::ifstream stream(file, std::ios::binary);
    if (!stream) throw FileError(file, "cannot be opened for reading (permission denied?)");
    const auto size = std::filesystem::file_size(file, error);
    if (!error && size == 0) throw FileError(file, "file is empty");
}

/// assimp 5.2.5's PLY reader loops forever on a header that never reaches `end_header`:
/// PLY::DOM::ParseHeader skips unknown header lines with IOStreamBuffer::getNextLine and
/// ignores its `false` at end of file, so the line buffer never empties
/// (tests/fuzz/findings/assimp-ply-hang.bin). Such a file is refused here, before assimp sees
/// it: the header must start with the magic line and contain an `end_header` line within the
/// first 1 MiB (real headers are a few hundred bytes).
///
/// Its post-processing also aborts (an ai_assert compiled into Debian's libassimp, in
/// TriangulateProcess) on a body shorter than the header declares (scene_import_fuzzer, seed 1):
/// the body must hold at least the declared elements — one value per scalar property and the
/// count of each list (ASCII: whitespace-separated values; binary: bytes) — or the file is
/// refused too.
void checkPlyBody(const std::filesystem::path& file, std::ifstream& stream,
                  const std::string& format, unsigned long long minimumValues,
                  unsigned long long minimumBytes)
{
    if (format == "ascii") {
        unsigned long long values = 0;
        std::string value;
        while (values < minimumValues && stream >> value)
            ++values;
        if (values < minimumValues)
            throw FileError(file, "malformed PLY: the header declares " +
                                      std::to_string(minimumValues) +
                                      " or more values, the body holds " + std::to_string(values));
    } else {
        const std::streampos bodyStart = stream.tellg();
        stream.seekg(0, std::ios::end);
        const auto bytes = static_cast<unsigned long long>(stream.tellg() - bodyStart);
        if (bodyStart >= 0 && bytes < minimumBytes)
            throw FileError(file,
                            "malformed PLY: the header declares " + std::to_string(minimumBytes) +
                                " or more bytes of data, the body has " + std::to_string(bytes));
    }
}

unsigned long long plyTypeSize(const std::string& type)
{
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "double" || type == "float64") return 8;
    return 4; // int, uint, float and their sized names
}

void checkPlyHeader(const std::filesystem::path& file)
{
    constexpr std::size_t headerLimit = 1 << 20;
    constexpr unsigned long long kCap = 1ull << 40; // keeps the sums below from overflowing
    std::ifstream stream(file, std::ios::binary);
    std::string line;
    std::size_t consumed = 0;
    bool first = true;
    std::string format;
    unsigned long long elementCount = 0, minimumValues = 0, minimumBytes = 0;
    while (consumed < headerLimit && std::getline(stream, line)) {
        consumed += line.size() + 1;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const std::size_t start = line.find_first_not_of(" \t");
        const std::string token =
            start == std::string::npos
                ? std::string()
                : line.substr(start, line.find_first_of(" \t", start) - start);
        if (first) {
            if (token != "ply" && token != "PLY")
                throw FileError(file, "malformed PLY: the first line must be 'ply'");
            first = false;
        } else if (token == "end_header") {
            checkPlyBody(file, stream, format, minimumValues, minimumBytes);
            return;
        } else {
            std::istringstream words(line);
            std::string keyword, a, b;
            words >> keyword >> a >> b;
            if (keyword == "format") {
                format = a;
            } else if (keyword == "element") {
                // assimp reads the digits an element's name starts with as its count (a name of
                // "6666666666666vertex" asked for 21 GB, scene_import_fuzzer), and a count's
                // leading digits whatever follows them: both are refused, and a count too long
                // to sum counts as the cap (the body check then refuses it).
                if (a.empty() || std::isdigit(static_cast<unsigned char>(a[0])))
                    throw FileError(file, "malformed PLY: element name '" + a +
                                              "': expected a name that does not start with a "
                                              "digit");
                if (b.empty() || b.find_first_not_of("0123456789") != std::string::npos)
                    throw FileError(file, "malformed PLY: element '" + a + "' has count '" + b +
                                              "': expected a whole number");
                elementCount = b.size() < 13 ? std::min(kCap, std::stoull(b)) : kCap;
            } else if (keyword == "property") {
                // A scalar takes one value; a list at least its count.
                minimumValues = std::min(kCap, minimumValues + elementCount);
                minimumBytes =
                    std::min(kCap, minimumBytes + elementCount * plyTypeSize(a == "list" ? b : a));
            }
        }
    }
    throw FileError(file, "malformed PLY: the header has no 'end_header' line" +
                              std::string(consumed >= headerLimit ? " in its first 1 MiB" : ""));
}

/// assimp 5.2.5's OFF reader allocates the vertex array for the count the header declares
/// before reading any vertex: a 115-byte file declaring 10^31 vertices asked for 5.7 GB
/// (scene_import_fuzzer). A header whose vertex or face count exceeds the file's size in bytes
/// (every vertex and face takes several bytes) is refused before assimp sees it.
void checkOffHeader(const std::filesystem::path& file)
{
    std::error_code error;
    const auto size = std::filesystem::file_size(file, error);
    if (error) return; // checkReadableFile already judged the file
    std::ifstream stream(file, std::ios::binary);
    std::string word;
    std::vector<std::string> words;
    while (words.size() < 4 && stream >> word) {
        if (word[0] == '#') { // a comment runs to the end of its line
            std::string rest;
            std::getline(stream, rest);
            continue;
        }
        words.push_back(word);
    }
    if (words.empty()) return;
    // assimp reads the vertex count right after the keyword, also without a space between
    // ("OFF0000000000002000…": the fuzzer's finding, 1.1e9 vertices after assimp's 32-bit
    // wrap-around, 13 GB touched): such digits are the first count.
    const std::size_t keyword = words[0].find("OFF");
    if (keyword == std::string::npos) return; // not the header assimp reads counts after
    if (keyword + 3 < words[0].size()) {
        const std::string digits = words[0].substr(keyword + 3);
        if (digits.find_first_not_of("0123456789") != std::string::npos) return; // assimp decides
        words.insert(words.begin() + 1, digits);
    }
    for (size_t k = 1; k < words.size() && k <= 2; ++k) {
        const std::string& count = words[k];
        if (count.empty() || count.find_first_not_of("0123456789") != std::string::npos) return;
        if (count.size() > 19 || std::stoull(count) > size)
            throw FileError(file, "malformed OFF: the header declares " + count + " " +
                                      (k == 1 ? "vertices" : "faces") + ", more than a file of " +
                                      std::to_string(size) + " bytes can hold");
    }
}

/// Rotation taking +Z up to +Y up (−90° about X): (x, y, z) → (x, z, −y).
Mat4 zUpToYUp()
{
    Mat4 m = Mat4::Identity();
    m.block<3, 3>(0, 0) << 1, 0, 0, 0, 0, 1, 0, -1, 0;
    return m;
}

/// The name of a node's first mesh; when readers split one mesh into parts named "base-0",
/// "base-1", … (assimp does for multi-primitive glTF meshes), "base".
std::string meshBaseName(const ImportedScene& scene, const SceneNode& node)
{
    const std::string& first = scene.meshes[static_cast<size_t>(node.meshes.front())].name;
    const size_t dash = first.find_last_of('-');
    if (dash == std::string::npos || dash == 0 || dash + 1 == first.size()) return first;
    const std::string base = first.substr(0, dash);
    for (size_t k = 0; k < node.meshes.size(); ++k) {
        const std::string& name = scene.meshes[static_cast<size_t>(node.meshes[k])].name;
        if (name != base + "-" + std::to_string(k)) return first;
    }
    return base;
}

} // namespace

const std::vector<std::string>& supportedSceneExtensions()
{
    static const std::vector<std::string> extensions = {".gltf", ".glb", ".obj", ".stl", ".ply",
                                                        ".fbx",  ".dae", ".3ds", ".ifc", ".3mf",
                                                        ".x3d",  ".off", ".amf", ".stp", ".step"};
    return extensions;
}

bool isSupportedSceneFile(const std::filesystem::path& file)
{
    const std::string extension = lowerCaseExtension(file);
    for (const std::string& supported : supportedSceneExtensions())
        if (supported == extension) return true;
    return false;
}

ImportedScene importScene(const std::filesystem::path& file, const ImportOptions& options)
{
    if (options.metresPerUnit &&
        !(std::isfinite(*options.metresPerUnit) && *options.metresPerUnit > 0.0))
        throw InvalidArgument("ImportOptions::metresPerUnit: expected a finite number > 0");
    if (!(std::isfinite(options.chordalTolerance) && options.chordalTolerance > 0.0))
        throw InvalidArgument("ImportOptions::chordalTolerance: expected metres > 0");
    if (!(std::isfinite(options.angularTolerance) && options.angularTolerance > 0.0))
        throw InvalidArgument("ImportOptions::angularTolerance: expected radians > 0");

    const std::string extension = lowerCaseExtension(file);
    if (!isSupportedSceneFile(file)) {
        std::string list;
        for (const std::string& supported : supportedSceneExtensions())
            list += (list.empty() ? "" : " ") + supported;
        throw FileError(file,
                        "unsupported scene format '" + extension + "' (supported: " + list + ")");
    }
    checkReadableFile(file);
    if (extension == ".ply") checkPlyHeader(file);
    if (extension == ".off") checkOffHeader(file);

    // The parser gets 85 % of the bar, our conversion the rest.
    detail::ProgressStage parsing(options, file, 0.0, 0.85);
    parsing.report(0.0);
    const bool step = isStep(extension);
    const detail::ReaderProgram program =
        step ? detail::ReaderProgram{detail::readerProgram("chaintube-step-reader", file), {}}
             : detail::ReaderProgram{detail::readerProgram("chaintube-scene-reader", file),
                                     {extension}};
    detail::ReaderResult read = detail::readInChildProcess(
        file,
        step ? std::string("STEP importer (OpenCASCADE)")
             : detail::assimpFormatName(extension) + " importer (assimp)",
        options, parsing, program);
    detail::ProgressStage converting(options, file, 0.85, 1.0);
    ImportedScene scene = detail::finaliseScene(std::move(read), file, options);
    converting.report(1.0);
    return scene;
}

namespace detail {

ImportedScene finaliseScene(ReaderResult&& result, const std::filesystem::path& file,
                            const ImportOptions& options)
{
    ImportedScene scene = std::move(result.scene);
    scene.file = file;
    if (scene.nodes.empty()) throw FileError(scene.file, "the file contains no scene nodes");

    // --- units and up axis ------------------------------------------------------------------
    SourceUnits& units = scene.sourceUnits;
    if (options.metresPerUnit) {
        units.metresPerUnit = *options.metresPerUnit;
        units.unitName = std::to_string(*options.metresPerUnit) + " m";
        units.unitSource = UnitSource::UserOverride;
    }
    if (options.upAxis) {
        units.upAxis = *options.upAxis;
        units.upAxisSource = UnitSource::UserOverride;
    }
    const double scale = options.metresPerUnit
                             ? *options.metresPerUnit * result.sourceUnitsPerReaderUnit
                             : result.metresPerReaderUnit;
    if (scale != 1.0) {
        // Scaling every translation and vertex is the same as S·M·S⁻¹ per node and S·v per
        // vertex: world positions scale, rotations and node scales are unchanged.
        for (SceneNode& node : scene.nodes)
            node.localTransform.block<3, 1>(0, 3) *= scale;
        for (SceneMesh& mesh : scene.meshes)
            for (float& coordinate : mesh.positions)
                coordinate = static_cast<float>(coordinate * scale);
    }
    if (units.upAxis == UpAxis::PositiveZ)
        scene.nodes[0].localTransform = zUpToYUp() * scene.nodes[0].localTransform;

    // --- names and paths ----------------------------------------------------------------------
    // Parents come before children, so one pass in node order sees each parent's path first.
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        SceneNode& node = scene.nodes[i];
        if (node.parent >= static_cast<int>(i))
            throw FileError(scene.file, "internal error: node order (parent after child)");
        if (node.name.empty() && !node.meshes.empty() &&
            !scene.meshes[static_cast<size_t>(node.meshes.front())].name.empty()) {
            node.name = meshBaseName(scene, node);
            node.generatedName = true;
        } else if (node.name.empty()) {
            std::string generated = "node";
            std::vector<int> indices;
            for (int child = static_cast<int>(i), parent = node.parent; parent >= 0;
                 child = parent, parent = scene.nodes[static_cast<size_t>(parent)].parent) {
                const auto& siblings = scene.nodes[static_cast<size_t>(parent)].children;
                indices.push_back(static_cast<int>(
                    std::find(siblings.begin(), siblings.end(), child) - siblings.begin()));
            }
            for (auto it = indices.rbegin(); it != indices.rend(); ++it)
                generated += "_" + std::to_string(*it);
            node.name = generated;
            node.generatedName = true;
        }
    }
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        SceneNode& node = scene.nodes[i];
        if (node.parent < 0) {
            std::string segment = node.name;
            std::replace(segment.begin(), segment.end(), '/', '_');
            node.path = "/" + segment;
        }
        std::map<std::string, int> used;
        for (int childIndex : node.children) {
            SceneNode& child = scene.nodes[static_cast<size_t>(childIndex)];
            std::string segment = child.name;
            std::replace(segment.begin(), segment.end(), '/', '_');
            const int occurrence = ++used[segment];
            if (occurrence > 1) {
                // Make sure "a#2" is not also a real sibling name.
                std::string candidate;
                int n = occurrence;
                do {
                    candidate = segment + "#" + std::to_string(n++);
                } while (used.count(candidate));
                used[candidate] = 1;
                segment = candidate;
            }
            child.path = node.path + "/" + segment;
        }
    }
    return scene;
}

} // namespace detail

} // namespace chaintube::formats
