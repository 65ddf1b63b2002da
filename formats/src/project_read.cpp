// Reading *.ctproj: a hand-written validator over nlohmann::json that reports the file, the
// JSON pointer and what was expected (no C++ JSON Schema library exists in Debian 12).
#include "chaintube/formats/project.h"
#include "chaintube/formats/project_hoses.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>

namespace chaintube::formats {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// Limits of the reader (formats/README.md, "Errors and limits"): a hostile or corrupt file is
// refused with a ProjectFormatError (a FileError for the size) instead of exhausting memory or
// the stack.
// Real projects are far below them (the 50-hose sample: 52 KB, 1,200 axis points).
constexpr std::size_t kMaxProjectFileBytes = std::size_t{64} << 20; // 64 MiB of JSON
constexpr int kMaxJsonDepth = 64;                                   // nesting of arrays and objects
constexpr std::size_t kMaxJsonValues = 2000000;  // values in the document (~150 MB DOM)
constexpr std::size_t kMaxProjectHoses = 100000; // hoses in one project
constexpr std::size_t kMaxRoutePoints = 100000;  // route points of one hose
// Axis points of all hoses together (segmentCount + 1 each; with segmentLength, the route
// length divided by it).
constexpr std::size_t kMaxProjectAxisPoints = 10000000;

std::string describe(const json& value)
{
    switch (value.type()) {
    case json::value_t::null:
        return "null";
    case json::value_t::boolean:
        return value.get<bool>() ? "true" : "false";
    case json::value_t::string:
        return value.dump();
    case json::value_t::array:
        return "an array";
    case json::value_t::object:
        return "an object";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
        return value.dump();
    default:
        return "an unsupported value";
    }
}

std::string escapePointerToken(const std::string& token)
{
    std::string escaped;
    for (char c : token) {
        if (c == '~')
            escaped += "~0";
        else if (c == '/')
            escaped += "~1";
        else
            escaped += c;
    }
    return escaped;
}

/// Where we are in the document; every accessor checks the type and range and throws
/// ProjectFormatError with this pointer.
class Cursor
{
public:
    Cursor(const json& value, std::string pointer, const fs::path& file, bool ignoreUnknown,
           std::vector<std::string>* ignored)
        : m_value(value), m_pointer(std::move(pointer)), m_file(file),
          m_ignoreUnknown(ignoreUnknown), m_ignored(ignored)
    {
    }

    [[noreturn]] void fail(const std::string& expected) const
    {
        throw ProjectFormatError(m_file, m_pointer, expected);
    }
    const std::string& pointer() const { return m_pointer; }
    const json& raw() const { return m_value; }

    /// Object with exactly these keys allowed (some required, checked by key()).
    const Cursor& object(std::initializer_list<const char*> allowed) const
    {
        if (!m_value.is_object()) fail("expected an object, got " + describe(m_value));
        for (const auto& [key, unused] : m_value.items()) {
            bool known = false;
            for (const char* name : allowed)
                known = known || key == name;
            if (known) continue;
            if (m_ignoreUnknown) {
                if (m_ignored) m_ignored->push_back(m_pointer + "/" + escapePointerToken(key));
                continue;
            }
            std::string list;
            for (const char* name : allowed)
                list += (list.empty() ? "" : ", ") + std::string(name);
            Cursor(m_value.at(key), m_pointer + "/" + escapePointerToken(key), m_file, false,
                   nullptr)
                .fail("unknown key \"" + key + "\" (expected one of: " + list + ")");
        }
        return *this;
    }
    bool has(const char* key) const { return m_value.is_object() && m_value.contains(key); }
    Cursor key(const char* name) const
    {
        if (!m_value.contains(name)) fail(std::string("missing required key \"") + name + "\"");
        return child(m_value.at(name), escapePointerToken(name));
    }
    std::optional<Cursor> optionalKey(const char* name) const
    {
        if (!m_value.contains(name)) return std::nullopt;
        return child(m_value.at(name), escapePointerToken(name));
    }
    size_t arraySize(size_t minimum = 0, size_t maximum = SIZE_MAX) const
    {
        if (!m_value.is_array()) fail("expected an array, got " + describe(m_value));
        if (m_value.size() < minimum || m_value.size() > maximum) {
            std::string range = maximum == SIZE_MAX ? "at least " + std::to_string(minimum)
                                : minimum == maximum
                                    ? "exactly " + std::to_string(minimum)
                                    : std::to_string(minimum) + " to " + std::to_string(maximum);
            fail("expected an array of " + range + " elements, got " +
                 std::to_string(m_value.size()));
        }
        return m_value.size();
    }
    Cursor operator[](size_t index) const
    {
        return child(m_value.at(index), std::to_string(index));
    }

    std::string string(bool allowEmpty = false) const
    {
        if (!m_value.is_string()) fail("expected a string, got " + describe(m_value));
        std::string text = m_value.get<std::string>();
        if (!allowEmpty && text.empty()) fail("expected a non-empty string");
        return text;
    }
    bool boolean() const
    {
        if (!m_value.is_boolean()) fail("expected true or false, got " + describe(m_value));
        return m_value.get<bool>();
    }
    /// A finite number in the interval; bounds written like "[0, 1)".
    double number(double low, bool lowInclusive, double high, bool highInclusive) const
    {
        const std::string range = std::string(lowInclusive ? "[" : "(") + formatBound(low) + ", " +
                                  formatBound(high) + (highInclusive ? "]" : ")");
        if (!m_value.is_number())
            fail("expected a number in " + range + ", got " + describe(m_value));
        const double value = m_value.get<double>();
        const bool aboveLow = lowInclusive ? value >= low : value > low;
        const bool belowHigh = highInclusive ? value <= high : value < high;
        if (!std::isfinite(value) || !aboveLow || !belowHigh)
            fail("expected a number in " + range + ", got " + describe(m_value));
        return value;
    }
    double anyFinite() const { return number(-HUGE_VAL, false, HUGE_VAL, false); }
    int integer(int low, int high) const
    {
        const std::string range = "[" + std::to_string(low) + ", " + std::to_string(high) + "]";
        if (!m_value.is_number_integer())
            fail("expected an integer in " + range + ", got " + describe(m_value));
        const auto value = m_value.get<long long>();
        if (value < low || value > high)
            fail("expected an integer in " + range + ", got " + describe(m_value));
        return static_cast<int>(value);
    }

private:
    static std::string formatBound(double bound)
    {
        if (bound == HUGE_VAL) return "inf";
        if (bound == -HUGE_VAL) return "-inf";
        if (bound == std::numbers::pi) return "pi";
        if (bound == 2.0 * std::numbers::pi) return "2pi";
        if (bound == -2.0 * std::numbers::pi) return "-2pi";
        if (bound == std::floor(bound) && std::abs(bound) < 1e15)
            return std::to_string(static_cast<long long>(bound));
        return json(bound).dump();
    }
    Cursor child(const json& value, const std::string& token) const
    {
        return Cursor(value, m_pointer + "/" + token, m_file, m_ignoreUnknown, m_ignored);
    }

    const json& m_value;
    std::string m_pointer;
    const fs::path& m_file;
    bool m_ignoreUnknown;
    std::vector<std::string>* m_ignored;
};

Vec3 readVec3(const Cursor& cursor)
{
    cursor.arraySize(3, 3);
    return {cursor[0].anyFinite(), cursor[1].anyFinite(), cursor[2].anyFinite()};
}

Material readMaterialValues(const Cursor& cursor, std::initializer_list<const char*> keys)
{
    cursor.object(keys);
    Material material;
    material.expansionCoefficient = cursor.key("expansionCoefficient").number(0, true, 1, false);
    const Cursor limit = cursor.key("bendLimit");
    limit.object({"minBendRadius", "deflectionAngle"});
    const bool radius = limit.has("minBendRadius");
    const bool angle = limit.has("deflectionAngle");
    if (radius == angle)
        limit.fail("expected exactly one of \"minBendRadius\" (metres) or "
                   "\"deflectionAngle\" (radians)");
    if (radius) {
        material.bendLimit = {BendLimit::Kind::MinBendRadius,
                              limit.key("minBendRadius").number(0, true, HUGE_VAL, false)};
    } else {
        material.bendLimit = {
            BendLimit::Kind::DeflectionAngle,
            limit.key("deflectionAngle").number(0, true, std::numbers::pi, false)};
    }
    return material;
}

ProfileSpec readProfile(const Cursor& cursor)
{
    if (!cursor.raw().is_object()) cursor.object({});
    ProfileSpec profile;
    const std::string shape = cursor.key("shape").string();
    if (shape == "circle") {
        cursor.object({"shape", "sides"});
        profile.shape = Profile::Shape::Circle;
        profile.sides = cursor.key("sides").integer(3, 1024);
    } else if (shape == "ellipse") {
        cursor.object({"shape", "semiAxisX", "semiAxisY", "sides"});
        profile.shape = Profile::Shape::Ellipse;
        profile.semiAxisX = cursor.key("semiAxisX").number(0, false, HUGE_VAL, false);
        profile.semiAxisY = cursor.key("semiAxisY").number(0, false, HUGE_VAL, false);
        profile.sides = cursor.key("sides").integer(3, 1024);
    } else if (shape == "rectangle") {
        cursor.object({"shape", "width", "height"});
        profile.shape = Profile::Shape::Rectangle;
        profile.width = cursor.key("width").number(0, false, HUGE_VAL, false);
        profile.height = cursor.key("height").number(0, false, HUGE_VAL, false);
    } else if (shape == "roundedRectangle") {
        cursor.object({"shape", "width", "height", "cornerRadius", "cornerSegments"});
        profile.shape = Profile::Shape::RoundedRectangle;
        profile.width = cursor.key("width").number(0, false, HUGE_VAL, false);
        profile.height = cursor.key("height").number(0, false, HUGE_VAL, false);
        const double largest = 0.5 * std::min(profile.width, profile.height);
        profile.cornerRadius = cursor.key("cornerRadius").number(0, false, largest, true);
        profile.cornerSegments = cursor.key("cornerSegments").integer(1, 64);
    } else if (shape == "polygon") {
        cursor.object({"shape", "points", "smoothAngle"});
        profile.shape = Profile::Shape::Polygon;
        const Cursor points = cursor.key("points");
        const size_t count = points.arraySize(3, 4096);
        for (size_t i = 0; i < count; ++i) {
            points[i].arraySize(2, 2);
            profile.points.push_back({points[i][0].anyFinite(), points[i][1].anyFinite()});
        }
        profile.smoothAngle = cursor.key("smoothAngle").number(0, true, std::numbers::pi, false);
    } else {
        cursor.key("shape").fail("expected one of \"circle\", \"ellipse\", \"rectangle\", "
                                 "\"roundedRectangle\", \"polygon\", got \"" +
                                 shape + "\"");
    }
    return profile;
}

Frame readFrame(const Cursor& cursor)
{
    cursor.object({"translation", "rotation"});
    Frame frame;
    frame.translation = readVec3(cursor.key("translation"));
    const Cursor rotation = cursor.key("rotation");
    rotation.arraySize(4, 4);
    // glTF order: x, y, z, w.
    frame.rotation =
        Quat(rotation[3].number(-1, true, 1, true), rotation[0].number(-1, true, 1, true),
             rotation[1].number(-1, true, 1, true), rotation[2].number(-1, true, 1, true));
    const double norm = frame.rotation.norm();
    if (std::abs(norm - 1.0) > 1e-6)
        rotation.fail("expected a unit quaternion [x, y, z, w] (length 1 ± 1e-6), got length " +
                      json(norm).dump());
    return frame;
}

/// Version "major.minor" → numbers; anything else fails at /version.
std::pair<int, int> readVersion(const Cursor& cursor)
{
    const std::string text = cursor.string();
    int major = -1, minor = -1;
    char dot = 0;
    std::istringstream stream(text);
    if (!(stream >> major >> dot >> minor) || dot != '.' || major < 0 || minor < 0 ||
        stream.peek() != EOF || text.find_first_not_of("0123456789.") != std::string::npos)
        cursor.fail("expected a version \"<major>.<minor>\" such as \"1.0\", got \"" + text + "\"");
    return {major, minor};
}

/// Version 0.9 (the prototype's layout) differs from 1.0 in two places per hose:
/// "diameterMm" (millimetres) instead of "outerDiameter" (metres), and "color": "#RRGGBBAA"
/// instead of "colour": [r, g, b, a]. Rewrites the document to 1.0; returns false if a value
/// it needs has the wrong type (the 1.0 reader then reports the precise error).
void migrateFrom0_9(json& document, const fs::path& file)
{
    document["version"] = "1.0";
    if (!document.contains("hoses") || !document["hoses"].is_array()) return;
    for (size_t i = 0; i < document["hoses"].size(); ++i) {
        json& hose = document["hoses"][i];
        if (!hose.is_object()) continue;
        const std::string pointer = "/hoses/" + std::to_string(i);
        if (hose.contains("diameterMm")) {
            if (!hose["diameterMm"].is_number())
                throw ProjectFormatError(file, pointer + "/diameterMm",
                                         "expected a number (millimetres), got " +
                                             describe(hose["diameterMm"]));
            hose["outerDiameter"] = hose["diameterMm"].get<double>() / 1000.0;
            hose.erase("diameterMm");
        }
        if (hose.contains("color")) {
            const json& color = hose["color"];
            std::string text = color.is_string() ? color.get<std::string>() : "";
            const bool valid =
                (text.size() == 7 || text.size() == 9) && text[0] == '#' &&
                text.find_first_not_of("0123456789abcdefABCDEF", 1) == std::string::npos;
            if (!valid)
                throw ProjectFormatError(file, pointer + "/color",
                                         "expected a colour \"#RRGGBB\" or \"#RRGGBBAA\", got " +
                                             describe(color));
            if (text.size() == 7) text += "ff";
            json rgba = json::array();
            for (int k = 0; k < 4; ++k)
                rgba.push_back(std::stoi(text.substr(1 + 2 * size_t(k), 2), nullptr, 16) / 255.0);
            hose["colour"] = rgba;
            hose.erase("color");
        }
    }
}

/// One entry of "motions" (1.4). `ids` and `moving` collect what earlier entries used.
PartMotion readMotion(const Cursor& entry, const Project& project, std::set<std::string>& ids,
                      std::set<std::pair<std::string, std::string>>& moving)
{
    if (!entry.raw().is_object()) entry.object({});
    PartMotion motion;
    const std::string kind = entry.key("kind").string();
    if (kind == "hinge") {
        entry.object({"id", "scene", "node", "kind", "axis", "point", "min", "max"});
        motion.kind = PartMotion::Kind::Hinge;
    } else if (kind == "slider") {
        entry.object({"id", "scene", "node", "kind", "axis", "min", "max"});
        motion.kind = PartMotion::Kind::Slider;
    } else {
        entry.key("kind").fail("expected \"hinge\" (a rotation about an axis through a point) or "
                               "\"slider\" (a translation along an axis), got \"" +
                               kind + "\"");
    }
    motion.id = entry.key("id").string();
    if (!ids.insert(motion.id).second)
        entry.key("id").fail("expected a unique motion id, \"" + motion.id + "\" is used twice");
    motion.scene = entry.key("scene").string();
    if (!project.findScene(motion.scene))
        entry.key("scene").fail("expected the id of a scene of this project, got \"" +
                                motion.scene + "\"");
    motion.node = entry.key("node").string();
    if (motion.node.front() != '/')
        entry.key("node").fail("expected a node path starting with '/', got \"" + motion.node +
                               "\"");
    if (!moving.insert({motion.scene, motion.node}).second)
        entry.key("node").fail("expected one motion per node, \"" + motion.node + "\" of scene \"" +
                               motion.scene + "\" has two");
    motion.axis = readVec3(entry.key("axis"));
    if (!(motion.axis.norm() > 1e-9))
        entry.key("axis").fail("expected a non-zero direction (world, length > 1e-9, need not be "
                               "unit), got length " +
                               json(motion.axis.norm()).dump());
    const bool hinge = motion.kind == PartMotion::Kind::Hinge;
    if (hinge) motion.point = readVec3(entry.key("point"));
    // A hinge turns at most one full turn either way; a slider's range is any finite distance.
    const double limit = hinge ? 2.0 * std::numbers::pi : HUGE_VAL;
    const std::string unit = hinge ? "radians" : "metres";
    motion.minimum = entry.key("min").number(-limit, hinge, HUGE_VAL, false);
    motion.maximum = entry.key("max").number(-HUGE_VAL, false, limit, hinge);
    if (!(motion.minimum < motion.maximum))
        entry.key("max").fail("expected max > min (" + unit + "), got min " +
                              json(motion.minimum).dump() + " and max " +
                              json(motion.maximum).dump());
    // Value 0 is the part's pose in the project: the sweep starts there.
    if (motion.minimum > 0.0)
        entry.key("min").fail("expected min <= 0 (" + unit +
                              "; value 0 is the part's pose in the project and lies in the "
                              "range), got " +
                              json(motion.minimum).dump());
    if (motion.maximum < 0.0)
        entry.key("max").fail("expected max >= 0 (" + unit +
                              "; value 0 is the part's pose in the project and lies in the "
                              "range), got " +
                              json(motion.maximum).dump());
    return motion;
}

Socket readSocket(const Cursor& entry, const Project& project)
{
    entry.object(
        {"id", "scene", "node", "position", "axis", "captureRadius", "captureAngle", "tag"});
    Socket socket;
    socket.id = entry.key("id").string();
    if (project.findSocket(socket.id))
        entry.key("id").fail("expected a unique socket id, \"" + socket.id + "\" is used twice");
    socket.scene = entry.key("scene").string();
    if (!project.findScene(socket.scene))
        entry.key("scene").fail("expected the id of a scene of this project, got \"" +
                                socket.scene + "\"");
    socket.node = entry.key("node").string();
    if (socket.node.front() != '/')
        entry.key("node").fail("expected a node path starting with '/', got \"" + socket.node +
                               "\"");
    socket.position = readVec3(entry.key("position"));
    socket.axis = readVec3(entry.key("axis"));
    if (!(socket.axis.norm() > 1e-9))
        entry.key("axis").fail("expected a non-zero direction (in the node's frame, length > "
                               "1e-9, need not be unit), got length " +
                               json(socket.axis.norm()).dump());
    socket.captureRadius = entry.key("captureRadius").number(0, false, HUGE_VAL, false);
    socket.captureAngle = entry.key("captureAngle").number(0, false, std::numbers::pi, true);
    socket.tag = entry.key("tag").string();
    return socket;
}

void checkPath(const Cursor& cursor, const std::string& written, const fs::path& projectDirectory,
               const NamedRoots& roots)
{
    try {
        if (classifyProjectPath(written) == PathKind::NamedRoot) {
            const std::string rootName = written.substr(0, written.find(':'));
            if (!roots.count(rootName)) return; // resolved when the scene is opened
        }
        resolveProjectPath(written, projectDirectory, roots);
    } catch (const PathError& error) {
        cursor.fail(error.what());
    }
}

Project readProject(const json& document, const fs::path& file, const ProjectLoadOptions& options,
                    ProjectLoadReport& report)
{
    const fs::path projectDirectory = fs::absolute(file).parent_path();
    const int fileMinor = [&] {
        const Cursor root(document, "", file, false, nullptr);
        return readVersion(root.key("version")).second;
    }();
    const bool newerMinor = fileMinor > kProjectFormatMinor;
    // Before 1.3 a hose was as long as its route: that length becomes its own (see below).
    const bool migrateLengths = fileMinor < 3;
    const Cursor root(document, "", file, newerMinor, &report.ignoredKeys);
    root.object({"format", "version", "name", "scenes", "materialPresets", "hoses", "poses",
                 "colliders", "motions", "checks", "sockets", "export"});

    Project project;
    project.name = root.key("name").string(true);

    // --- scenes -------------------------------------------------------------------------------
    const Cursor scenes = root.key("scenes");
    for (size_t i = 0, n = scenes.arraySize(); i < n; ++i) {
        const Cursor entry = scenes[i];
        entry.object({"id", "path", "import"});
        SceneReference scene;
        scene.id = entry.key("id").string();
        if (project.findScene(scene.id))
            entry.key("id").fail("expected a unique scene id, \"" + scene.id + "\" is used twice");
        scene.path = entry.key("path").string();
        checkPath(entry.key("path"), scene.path, projectDirectory, options.roots);
        const Cursor import = entry.key("import");
        import.object(
            {"metresPerUnit", "upAxis", "chordalTolerance", "angularTolerance", "placement"});
        if (auto unit = import.optionalKey("metresPerUnit"))
            scene.import.metresPerUnit = unit->number(0, false, HUGE_VAL, false);
        if (auto up = import.optionalKey("upAxis")) {
            const std::string axis = up->string();
            if (axis == "+Y")
                scene.import.upAxis = UpAxis::PositiveY;
            else if (axis == "+Z")
                scene.import.upAxis = UpAxis::PositiveZ;
            else
                up->fail("expected \"+Y\" or \"+Z\", got \"" + axis + "\"");
        }
        scene.import.chordalTolerance =
            import.key("chordalTolerance").number(0, false, HUGE_VAL, false);
        scene.import.angularTolerance =
            import.key("angularTolerance").number(0, false, std::numbers::pi, true);
        if (const auto placement = import.optionalKey("placement")) // 1.3
            scene.import.placement = readVec3(*placement);
        project.scenes.push_back(std::move(scene));
    }

    // --- material presets ---------------------------------------------------------------------
    const Cursor presets = root.key("materialPresets");
    for (size_t i = 0, n = presets.arraySize(); i < n; ++i) {
        const Cursor entry = presets[i];
        MaterialPreset preset;
        preset.material =
            readMaterialValues(entry, {"name", "description", "expansionCoefficient", "bendLimit"});
        preset.name = entry.key("name").string();
        if (project.findPreset(preset.name))
            entry.key("name").fail("expected a unique preset name, \"" + preset.name +
                                   "\" is used twice");
        preset.description = entry.key("description").string(true);
        project.materialPresets.push_back(std::move(preset));
    }

    // --- hoses --------------------------------------------------------------------------------
    const Cursor hoses = root.key("hoses");
    std::set<std::string> hoseIds;
    double projectAxisPoints = 0; // limit: kMaxProjectAxisPoints (a hostile file must not OOM)
    for (size_t i = 0, n = hoses.arraySize(0, kMaxProjectHoses); i < n; ++i) {
        const Cursor entry = hoses[i];
        entry.object({"id", "name", "route", "length", "material", "profile", "outerDiameter",
                      "segmentCount", "segmentLength", "colour", "roughness", "attachments",
                      "clips", "gravity", "torsion", "fittingsAllowance", "plugs"});
        HoseDefinition hose;
        hose.id = entry.key("id").string();
        if (!hoseIds.insert(hose.id).second)
            entry.key("id").fail("expected a unique hose id, \"" + hose.id + "\" is used twice");
        hose.name = entry.key("name").string(true);

        const Cursor route = entry.key("route");
        for (size_t p = 0, count = route.arraySize(2, kMaxRoutePoints); p < count; ++p) {
            hose.route.push_back(readVec3(route[p]));
            if (p > 0 && hose.route[p] == hose.route[p - 1])
                route[p].fail("expected a route point distinct from the previous one");
        }
        if (const auto length = entry.optionalKey("length")) // 1.3
            hose.length = length->number(0, false, HUGE_VAL, false);

        const Cursor material = entry.key("material");
        if (material.raw().is_string()) {
            hose.material = PresetName{material.string()};
            if (!project.findPreset(std::get<PresetName>(hose.material).name))
                material.fail("expected the name of a material preset of this project, got \"" +
                              std::get<PresetName>(hose.material).name + "\"");
        } else if (material.raw().is_object()) {
            hose.material = readMaterialValues(material, {"expansionCoefficient", "bendLimit"});
        } else {
            material.fail("expected a preset name (string) or an object {expansionCoefficient, "
                          "bendLimit}, got " +
                          describe(material.raw()));
        }

        hose.profile = readProfile(entry.key("profile"));
        hose.outerDiameter = entry.key("outerDiameter").number(0, false, HUGE_VAL, false);
        const bool byCount = entry.has("segmentCount");
        if (byCount == entry.has("segmentLength"))
            entry.fail("expected exactly one of \"segmentCount\" or \"segmentLength\"");
        if (byCount) {
            hose.segmentCount = entry.key("segmentCount").integer(1, 1000000);
        } else {
            hose.segmentCount = 0;
            hose.segmentLength = entry.key("segmentLength").number(0, false, HUGE_VAL, false);
        }
        double routeLength = 0;
        for (size_t p = 1; p < hose.route.size(); ++p)
            routeLength += (hose.route[p] - hose.route[p - 1]).norm();
        projectAxisPoints +=
            1.0 + (byCount ? double(hose.segmentCount)
                           : std::min(1e7, hose.length.value_or(routeLength) / hose.segmentLength));
        if (projectAxisPoints > double(kMaxProjectAxisPoints))
            entry.key(byCount ? "segmentCount" : "segmentLength")
                .fail("the project's hoses together would have more than " +
                      std::to_string(kMaxProjectAxisPoints) + " axis points (limit)");

        const Cursor colour = entry.key("colour");
        colour.arraySize(4, 4);
        hose.colour = {colour[0].number(0, true, 1, true), colour[1].number(0, true, 1, true),
                       colour[2].number(0, true, 1, true), colour[3].number(0, true, 1, true)};
        hose.roughness = entry.key("roughness").number(0, true, 1, true);

        const Cursor attachments = entry.key("attachments");
        const int maxPoint = byCount ? hose.segmentCount : 1000000;
        for (size_t a = 0, count = attachments.arraySize(); a < count; ++a) {
            const Cursor item = attachments[a];
            item.object({"scene", "node", "offset", "points"});
            HoseAttachment attachment;
            attachment.scene = item.key("scene").string();
            if (!project.findScene(attachment.scene))
                item.key("scene").fail("expected the id of a scene of this project, got \"" +
                                       attachment.scene + "\"");
            attachment.node = item.key("node").string();
            if (attachment.node.front() != '/')
                item.key("node").fail("expected a node path starting with '/', got \"" +
                                      attachment.node + "\"");
            attachment.offset = readFrame(item.key("offset"));
            const Cursor points = item.key("points");
            points.arraySize(2, 2);
            attachment.firstPoint = points[0].integer(0, maxPoint);
            attachment.lastPoint = points[1].integer(attachment.firstPoint, maxPoint);
            for (const HoseAttachment& other : hose.attachments)
                if (attachment.firstPoint <= other.lastPoint &&
                    other.firstPoint <= attachment.lastPoint)
                    points.fail("expected a point range not overlapping another attachment's [" +
                                std::to_string(other.firstPoint) + ", " +
                                std::to_string(other.lastPoint) + "]");
            hose.attachments.push_back(std::move(attachment));
        }
        if (const auto clips = entry.optionalKey("clips")) { // 1.5
            for (size_t c = 0, count = clips->arraySize(); c < count; ++c) {
                const Cursor item = (*clips)[c];
                item.object({"scene", "node", "offset", "place", "hold", "slideMin", "slideMax"});
                HoseClip clip;
                clip.scene = item.key("scene").string();
                if (!project.findScene(clip.scene))
                    item.key("scene").fail("expected the id of a scene of this project, got \"" +
                                           clip.scene + "\"");
                clip.node = item.key("node").string();
                if (clip.node.front() != '/')
                    item.key("node").fail("expected a node path starting with '/', got \"" +
                                          clip.node + "\"");
                clip.offset = readFrame(item.key("offset"));
                clip.place = item.key("place").number(0, true, HUGE_VAL, false);
                const std::string hold = item.key("hold").string();
                if (hold == toString(Hold::Sliding))
                    clip.hold = Hold::Sliding;
                else if (hold == toString(Hold::SlidingTurning))
                    clip.hold = Hold::SlidingTurning;
                else
                    item.key("hold").fail("expected \"sliding\" or \"sliding-turning\", got \"" +
                                          hold + "\"");
                if (const auto min = item.optionalKey("slideMin"))
                    clip.slideMin = min->number(0, true, clip.place, true);
                if (const auto max = item.optionalKey("slideMax"))
                    clip.slideMax = max->number(clip.place, true, HUGE_VAL, false);
                hose.clips.push_back(std::move(clip));
            }
        }
        if (const auto gravity = entry.optionalKey("gravity")) { // 1.2
            gravity->object({"enabled", "direction"});
            hose.gravity.enabled = gravity->key("enabled").boolean();
            hose.gravity.direction = readVec3(gravity->key("direction"));
            if (hose.gravity.direction.squaredNorm() == 0.0)
                gravity->key("direction")
                    .fail("expected a non-zero direction (world, need not be unit)");
        }
        if (const auto torsion = entry.optionalKey("torsion")) { // 1.2
            torsion->object({"enabled", "twistLimit"});
            hose.torsion.enabled = torsion->key("enabled").boolean();
            hose.torsion.twistLimit =
                torsion->key("twistLimit").number(0, false, 3.141592653589793, true);
        }
        if (const auto allowance = entry.optionalKey("fittingsAllowance")) // 1.6
            hose.fittingsAllowance = allowance->number(0, true, HUGE_VAL, false);
        if (const auto plugs = entry.optionalKey("plugs")) { // 1.7
            plugs->object({"start", "end"});
            if (const auto start = plugs->optionalKey("start")) hose.plugs.start = start->string();
            if (const auto end = plugs->optionalKey("end")) hose.plugs.end = end->string();
        }
        if (migrateLengths && !hose.length) {
            // The length the hose had when the file was written. A hose that cannot be laid
            // out (e.g. a profile out of range) stays without one: building it reports why.
            try {
                hose.length = routeRestLength(project, hose);
            } catch (const InvalidArgument&) {
            }
        }
        project.hoses.push_back(std::move(hose));
    }

    // --- pose overrides (1.1) -----------------------------------------------------------------
    if (const auto poses = root.optionalKey("poses")) {
        std::set<std::pair<std::string, std::string>> posed;
        for (size_t i = 0, n = poses->arraySize(); i < n; ++i) {
            const Cursor entry = (*poses)[i];
            entry.object({"scene", "node", "matrix"});
            NodePose pose;
            pose.scene = entry.key("scene").string();
            if (!project.findScene(pose.scene))
                entry.key("scene").fail("expected the id of a scene of this project, got \"" +
                                        pose.scene + "\"");
            pose.node = entry.key("node").string();
            if (pose.node.front() != '/')
                entry.key("node").fail("expected a node path starting with '/', got \"" +
                                       pose.node + "\"");
            if (!posed.insert({pose.scene, pose.node}).second)
                entry.key("node").fail("expected one pose per node, \"" + pose.node +
                                       "\" of scene \"" + pose.scene + "\" has two");
            const Cursor matrix = entry.key("matrix");
            matrix.arraySize(16, 16);
            for (int k = 0; k < 16; ++k) // column-major, as glTF
                pose.localTransform(k % 4, k / 4) = matrix[size_t(k)].anyFinite();
            for (int column = 0; column < 4; ++column)
                if (pose.localTransform(3, column) != (column == 3 ? 1.0 : 0.0))
                    matrix[size_t(4 * column + 3)].fail(
                        "expected an affine matrix: its last row (elements 3, 7, 11, 15 in "
                        "column-major order) must be 0, 0, 0, 1");
            const double determinant = pose.localTransform.topLeftCorner<3, 3>().determinant();
            if (!(std::abs(determinant) > 1e-12))
                matrix.fail("expected an invertible transform (|det| of the 3x3 block > 1e-12), "
                            "got det " +
                            json(determinant).dump());
            project.poses.push_back(std::move(pose));
        }
    }

    // --- colliders (1.2) -----------------------------------------------------------------------
    if (const auto colliders = root.optionalKey("colliders")) {
        std::set<std::pair<std::string, std::string>> flagged;
        for (size_t i = 0, n = colliders->arraySize(); i < n; ++i) {
            const Cursor entry = (*colliders)[i];
            entry.object({"scene", "node"});
            ColliderNode collider;
            collider.scene = entry.key("scene").string();
            if (!project.findScene(collider.scene))
                entry.key("scene").fail("expected the id of a scene of this project, got \"" +
                                        collider.scene + "\"");
            collider.node = entry.key("node").string();
            if (collider.node.front() != '/')
                entry.key("node").fail("expected a node path starting with '/', got \"" +
                                       collider.node + "\"");
            if (!flagged.insert({collider.scene, collider.node}).second)
                entry.key("node").fail("expected each collider node once, \"" + collider.node +
                                       "\" of scene \"" + collider.scene + "\" is listed twice");
            project.colliders.push_back(std::move(collider));
        }
    }

    // --- motions (1.4) -------------------------------------------------------------------------
    if (const auto motions = root.optionalKey("motions")) {
        std::set<std::string> ids;
        std::set<std::pair<std::string, std::string>> moving;
        for (size_t i = 0, n = motions->arraySize(); i < n; ++i)
            project.motions.push_back(readMotion((*motions)[i], project, ids, moving));
    }

    // --- checks (1.6) -------------------------------------------------------------------------
    if (const auto checks = root.optionalKey("checks")) {
        checks->object({"clearance"});
        if (const auto clearance = checks->optionalKey("clearance"))
            project.checks.clearance = clearance->number(0, true, HUGE_VAL, false);
    }

    // --- sockets (1.7) ------------------------------------------------------------------------
    if (const auto sockets = root.optionalKey("sockets"))
        for (size_t i = 0, n = sockets->arraySize(); i < n; ++i)
            project.sockets.push_back(readSocket((*sockets)[i], project));

    // --- export -------------------------------------------------------------------------------
    const Cursor exportSettings = root.key("export");
    exportSettings.object({"format", "path", "includeScene"});
    project.exportSettings.format = exportSettings.key("format").string();
    if (project.exportSettings.format != "glb" && project.exportSettings.format != "gltf")
        exportSettings.key("format").fail("expected \"glb\" or \"gltf\", got \"" +
                                          project.exportSettings.format + "\"");
    project.exportSettings.path = exportSettings.key("path").string(true);
    if (!project.exportSettings.path.empty())
        checkPath(exportSettings.key("path"), project.exportSettings.path, projectDirectory,
                  options.roots);
    project.exportSettings.includeScene = exportSettings.key("includeScene").boolean();
    return project;
}

} // namespace

Project parseProject(std::string_view text, const fs::path& file, const ProjectLoadOptions& options,
                     ProjectLoadReport* report)
{
    json document;
    try {
        // Checked in one linear pass before parsing, so that a hostile document (10^7 empty
        // objects, nesting 10^5 deep) never becomes a DOM larger than the memory.
        std::size_t values = 0;
        int depth = 0;
        bool inString = false, escaped = false;
        for (const char c : text) {
            if (inString) {
                if (escaped)
                    escaped = false;
                else if (c == '\\')
                    escaped = true;
                else if (c == '"')
                    inString = false;
                continue;
            }
            if (c == '"') inString = true;
            if (c == '[' || c == '{') {
                if (++depth > kMaxJsonDepth)
                    throw ProjectFormatError(file, "",
                                             "JSON nested deeper than " +
                                                 std::to_string(kMaxJsonDepth) + " levels (limit)");
            } else if (c == ']' || c == '}') {
                --depth;
            }
            if ((c == ',' || c == '[' || c == '{') && ++values > kMaxJsonValues)
                throw ProjectFormatError(file, "",
                                         "more than " + std::to_string(kMaxJsonValues) +
                                             " JSON values (limit)");
        }
        document = json::parse(text.begin(), text.end());
    } catch (const json::exception& error) { // parse_error, or out_of_range for 1e400
        // nlohmann reports "[json.exception.parse_error.101] parse error at line 3, column 5:
        // syntax error …": keep the part after the exception id.
        std::string message = error.what();
        const size_t bracket = message.find("] ");
        if (bracket != std::string::npos) message = message.substr(bracket + 2);
        throw ProjectFormatError(file, "", "not valid JSON: " + message);
    }
    ProjectLoadReport localReport;
    ProjectLoadReport& out = report ? *report : localReport;
    out = {};

    const Cursor root(document, "", file, false, nullptr);
    if (!document.is_object()) root.fail("expected a JSON object, got " + describe(document));
    const std::string format = root.key("format").string(true);
    if (format != "chaintube-project")
        root.key("format").fail("expected \"chaintube-project\", got \"" + format + "\"");
    const auto [major, minor] = readVersion(root.key("version"));
    out.fileVersion = root.key("version").string();
    if (major > kProjectFormatMajor)
        root.key("version").fail("this file was written in project format " + out.fileVersion +
                                 ", newer than this ChainTube understands (up to " +
                                 std::to_string(kProjectFormatMajor) +
                                 ".x); update ChainTube to open it");
    if (major == 0) {
        if (minor != 9)
            root.key("version").fail("expected version 0.9 or 1.x; version " + out.fileVersion +
                                     " is not supported");
        migrateFrom0_9(document, file);
        out.migrated = true;
    }
    // 1.0 → 1.1 added only the optional "poses", 1.1 → 1.2 the optional per-hose "gravity" and
    // "torsion" (off when absent) and "colliders" (none): nothing to rewrite; 1.2 → 1.3 the
    // hose's "length", which readProject() sets from the route; 1.3 → 1.4 the optional
    // "motions" (none); 1.6 → 1.7 the optional "sockets" and hose "plugs" (none).
    if (major == 1 && minor < kProjectFormatMinor) out.migrated = true;
    return readProject(document, file, options, out);
}

Project loadProject(const fs::path& file, const ProjectLoadOptions& options,
                    ProjectLoadReport* report)
{
    std::error_code error;
    if (!fs::exists(file, error)) throw FileError(file, "no such file");
    if (fs::is_directory(file, error)) throw FileError(file, "is a directory, not a project file");
    if (fs::is_regular_file(file, error) && fs::file_size(file, error) > kMaxProjectFileBytes)
        throw FileError(file, "file is larger than " + std::to_string(kMaxProjectFileBytes >> 20) +
                                  " MiB (limit for project files)");
    std::ifstream stream(file, std::ios::binary);
    if (!stream) throw FileError(file, "cannot be opened for reading");
    std::ostringstream contents;
    contents << stream.rdbuf();
    if (stream.bad()) throw FileError(file, "reading failed");
    const std::string text = contents.str();
    if (text.empty()) throw FileError(file, "file is empty");
    if (text.size() > kMaxProjectFileBytes)
        throw FileError(file, "file is larger than " + std::to_string(kMaxProjectFileBytes >> 20) +
                                  " MiB (limit for project files)");
    return parseProject(text, file, options, report);
}

} // namespace chaintube::formats
