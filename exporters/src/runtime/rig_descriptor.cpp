#include "chaintube/export/rig_descriptor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>

namespace chaintube::rig {

using Json = nlohmann::ordered_json;

DescriptorError::DescriptorError(std::string source, std::string pointer, std::string expected)
    : Error(source + ": " + (pointer.empty() ? std::string("(document)") : pointer) + ": " +
            expected),
      m_source(std::move(source)), m_pointer(std::move(pointer))
{
}

namespace {

size_t parameterCount(Profile::Shape shape)
{
    switch (shape) {
    case Profile::Shape::Circle:
        return 2;
    case Profile::Shape::Ellipse:
        return 3;
    case Profile::Shape::Rectangle:
        return 2;
    case Profile::Shape::RoundedRectangle:
        return 4;
    case Profile::Shape::Polygon:
        return 1;
    }
    return 0;
}

Json vec3(const Vec3& v)
{
    return Json::array({v.x(), v.y(), v.z()});
}
Json quat(const Quat& q)
{
    return Json::array({q.x(), q.y(), q.z(), q.w()});
}
Json frame(const Frame& f)
{
    return Json{{"translation", vec3(f.translation)}, {"rotation", quat(f.rotation)}};
}
template <typename T> Json list(const std::vector<T>& values)
{
    Json array = Json::array();
    for (const T& value : values)
        array.push_back(value);
    return array;
}

/// Reads typed values out of the document, naming the JSON pointer on every failure.
class Reader
{
public:
    explicit Reader(std::string source) : m_source(std::move(source)) {}

    [[noreturn]] void fail(const std::string& pointer, const std::string& expected) const
    {
        throw DescriptorError(m_source, pointer, expected);
    }
    const Json& member(const Json& object, const std::string& pointer, const char* key) const
    {
        const auto it = object.find(key);
        if (it == object.end()) fail(pointer + "/" + key, "missing (required)");
        return *it;
    }
    const Json& object(const Json& value, const std::string& pointer) const
    {
        if (!value.is_object()) fail(pointer, "expected an object, got " + describe(value));
        return value;
    }
    const Json& array(const Json& value, const std::string& pointer) const
    {
        if (!value.is_array()) fail(pointer, "expected an array, got " + describe(value));
        return value;
    }
    double number(const Json& value, const std::string& pointer) const
    {
        if (!value.is_number()) fail(pointer, "expected a number, got " + describe(value));
        const double result = value.get<double>();
        if (!std::isfinite(result)) fail(pointer, "expected a finite number");
        return result;
    }
    double number(const Json& value, const std::string& pointer, double low, double high,
                  const char* range) const
    {
        const double result = number(value, pointer);
        if (!(result >= low && result <= high))
            fail(pointer, std::string("expected a number in ") + range + ", got " + value.dump());
        return result;
    }
    int integer(const Json& value, const std::string& pointer, int low) const
    {
        if (!value.is_number_integer())
            fail(pointer, "expected an integer, got " + describe(value));
        const auto result = value.get<long long>();
        if (result < low || result > 1'000'000'000)
            fail(pointer, "expected an integer ≥ " + std::to_string(low) + ", got " + value.dump());
        return static_cast<int>(result);
    }
    bool boolean(const Json& value, const std::string& pointer) const
    {
        if (!value.is_boolean()) fail(pointer, "expected true or false, got " + describe(value));
        return value.get<bool>();
    }
    void onlyKeys(const Json& object, const std::string& pointer,
                  std::initializer_list<const char*> keys) const
    {
        for (auto it = object.begin(); it != object.end(); ++it)
            if (std::none_of(keys.begin(), keys.end(),
                             [&](const char* key) { return it.key() == key; }))
                fail(pointer + "/" + it.key(), "unknown member");
    }
    std::string string(const Json& value, const std::string& pointer) const
    {
        if (!value.is_string()) fail(pointer, "expected a string, got " + describe(value));
        return value.get<std::string>();
    }
    Vec3 vector3(const Json& value, const std::string& pointer) const
    {
        array(value, pointer);
        if (value.size() != 3) fail(pointer, "expected 3 numbers [x, y, z]");
        return {number(value[0], pointer + "/0"), number(value[1], pointer + "/1"),
                number(value[2], pointer + "/2")};
    }
    Quat quaternion(const Json& value, const std::string& pointer) const
    {
        array(value, pointer);
        if (value.size() != 4) fail(pointer, "expected 4 numbers [x, y, z, w]");
        Quat q(number(value[3], pointer + "/3"), number(value[0], pointer + "/0"),
               number(value[1], pointer + "/1"), number(value[2], pointer + "/2"));
        if (std::abs(q.norm() - 1.0) > 1e-6)
            fail(pointer, "expected a unit quaternion (|q| = 1 within 1e-6), got |q| = " +
                              std::to_string(q.norm()));
        return q;
    }
    Frame frame(const Json& value, const std::string& pointer) const
    {
        object(value, pointer);
        Frame result;
        result.translation =
            vector3(member(value, pointer, "translation"), pointer + "/translation");
        result.rotation = quaternion(member(value, pointer, "rotation"), pointer + "/rotation");
        result.rotation.normalize();
        return result;
    }
    std::vector<double> numbers(const Json& value, const std::string& pointer) const
    {
        array(value, pointer);
        std::vector<double> result;
        result.reserve(value.size());
        for (size_t i = 0; i < value.size(); ++i)
            result.push_back(number(value[i], pointer + "/" + std::to_string(i)));
        return result;
    }
    std::vector<int> integers(const Json& value, const std::string& pointer, int low) const
    {
        array(value, pointer);
        std::vector<int> result;
        result.reserve(value.size());
        for (size_t i = 0; i < value.size(); ++i)
            result.push_back(integer(value[i], pointer + "/" + std::to_string(i), low));
        return result;
    }
    static std::string describe(const Json& value)
    {
        if (value.is_null()) return "null";
        if (value.is_array()) return "an array";
        if (value.is_object()) return "an object";
        if (value.is_string()) return "a string";
        if (value.is_boolean()) return "a boolean";
        return value.dump();
    }

private:
    std::string m_source;
};

Profile::Shape shapeOf(const std::string& name, const Reader& reader, const std::string& pointer)
{
    for (Profile::Shape shape :
         {Profile::Shape::Circle, Profile::Shape::Ellipse, Profile::Shape::Rectangle,
          Profile::Shape::RoundedRectangle, Profile::Shape::Polygon})
        if (name == shapeName(shape)) return shape;
    reader.fail(pointer, "expected one of circle, ellipse, rectangle, roundedRectangle, polygon; "
                         "got \"" +
                             name + "\"");
}

RigMotion readMotion(const Json& value, const std::string& at, const Reader& r)
{
    constexpr double kTwoPi = 6.283185307179586;
    r.object(value, at);
    RigMotion motion;
    motion.id = r.string(r.member(value, at, "id"), at + "/id");
    if (motion.id.empty()) r.fail(at + "/id", "expected a non-empty id");
    motion.node = r.integer(r.member(value, at, "node"), at + "/node", 0);
    const std::string kind = r.string(r.member(value, at, "kind"), at + "/kind");
    if (kind == motionKindName(RigMotion::Kind::Hinge))
        motion.kind = RigMotion::Kind::Hinge;
    else if (kind == motionKindName(RigMotion::Kind::Slider))
        motion.kind = RigMotion::Kind::Slider;
    else
        r.fail(at + "/kind", "expected \"hinge\" or \"slider\", got \"" + kind + "\"");
    const Vec3 axis = r.vector3(r.member(value, at, "axis"), at + "/axis");
    if (!(std::abs(axis.norm() - 1.0) <= 1e-6))
        r.fail(at + "/axis", "expected a unit vector (glTF world)");
    motion.axis = axis.normalized();
    const bool hinge = motion.kind == RigMotion::Kind::Hinge;
    if (hinge) motion.point = r.vector3(r.member(value, at, "point"), at + "/point");
    const double bound = hinge ? kTwoPi : std::numeric_limits<double>::max();
    const char* unit = hinge ? "radians in [-2π, 0]" : "metres <= 0";
    motion.minimum = r.number(r.member(value, at, "min"), at + "/min");
    motion.maximum = r.number(r.member(value, at, "max"), at + "/max");
    if (!(motion.minimum <= 0.0 && motion.minimum >= -bound))
        r.fail(at + "/min", std::string("expected ") + unit + " (value 0 is the exported pose)");
    if (!(motion.maximum >= 0.0 && motion.maximum <= bound && motion.maximum > motion.minimum))
        r.fail(at + "/max", std::string("expected ") +
                                (hinge ? "radians in [0, 2π]" : "metres >= 0") + " and above min");
    if (hinge)
        r.onlyKeys(value, at, {"id", "node", "kind", "axis", "point", "min", "max"});
    else
        r.onlyKeys(value, at, {"id", "node", "kind", "axis", "min", "max"});
    return motion;
}

RigSocket readSocket(const Json& value, const std::string& at, const Reader& r)
{
    r.object(value, at);
    r.onlyKeys(value, at,
               {"id", "node", "nodeName", "position", "axis", "worldPosition", "worldAxis",
                "captureRadius", "captureAngle", "tag"});
    RigSocket socket;
    socket.id = r.string(r.member(value, at, "id"), at + "/id");
    if (socket.id.empty()) r.fail(at + "/id", "expected a non-empty id");
    socket.node = r.integer(r.member(value, at, "node"), at + "/node", -1);
    if (value.contains("nodeName")) socket.nodeName = r.string(value["nodeName"], at + "/nodeName");
    socket.position = r.vector3(r.member(value, at, "position"), at + "/position");
    socket.worldPosition = r.vector3(r.member(value, at, "worldPosition"), at + "/worldPosition");
    for (const char* key : {"axis", "worldAxis"}) {
        const Vec3 axis = r.vector3(r.member(value, at, key), at + "/" + key);
        if (!(std::abs(axis.norm() - 1.0) <= 1e-6))
            r.fail(at + "/" + key, "expected a unit vector (length 1 within 1e-6)");
        (std::string(key) == "axis" ? socket.axis : socket.worldAxis) = axis.normalized();
    }
    socket.captureRadius = r.number(r.member(value, at, "captureRadius"), at + "/captureRadius");
    if (!(socket.captureRadius > 0.0))
        r.fail(at + "/captureRadius", "expected metres > 0, got " + value["captureRadius"].dump());
    socket.captureAngle = r.number(r.member(value, at, "captureAngle"), at + "/captureAngle");
    if (!(socket.captureAngle > 0.0 && socket.captureAngle <= 3.141592653589793))
        r.fail(at + "/captureAngle",
               "expected radians in (0, π], got " + value["captureAngle"].dump());
    socket.tag = r.string(r.member(value, at, "tag"), at + "/tag");
    if (socket.tag.empty()) r.fail(at + "/tag", "expected a non-empty tag");
    return socket;
}

RigHose readHose(const Json& value, const std::string& at, const Reader& r)
{
    r.object(value, at);
    RigHose hose;
    hose.id = r.string(r.member(value, at, "id"), at + "/id");
    hose.name = r.string(r.member(value, at, "name"), at + "/name");
    if (value.contains("static")) {
        if (!value["static"].is_boolean())
            r.fail(at + "/static",
                   "expected true or false, got " + Reader::describe(value["static"]));
        hose.isStatic = value["static"].get<bool>();
    }
    hose.meshNode = r.integer(r.member(value, at, "mesh"), at + "/mesh", -1);
    hose.skin = r.integer(r.member(value, at, "skin"), at + "/skin", -1);
    hose.rigNode = r.integer(r.member(value, at, "rig"), at + "/rig", -1);
    hose.jointNodes = r.integers(r.member(value, at, "joints"), at + "/joints", -1);
    const Json& axis = r.array(r.member(value, at, "axis"), at + "/axis");
    for (size_t i = 0; i < axis.size(); ++i)
        hose.axis.push_back(r.vector3(axis[i], at + "/axis/" + std::to_string(i)));
    const int points = hose.pointCount();
    if (points < 2) r.fail(at + "/axis", "expected at least 2 axis points");
    if (hose.skin >= 0 && hose.jointNodes.size() != axis.size())
        r.fail(at + "/joints", "expected one joint per axis point (" + std::to_string(points) +
                                   "), got " + std::to_string(hose.jointNodes.size()));
    hose.restLengths = r.numbers(r.member(value, at, "restLengths"), at + "/restLengths");
    if (hose.restLengths.size() != axis.size() - 1)
        r.fail(at + "/restLengths", "expected " + std::to_string(points - 1) +
                                        " segment lengths, got " +
                                        std::to_string(hose.restLengths.size()));
    for (size_t s = 0; s < hose.restLengths.size(); ++s)
        if (!(hose.restLengths[s] > 0.0))
            r.fail(at + "/restLengths/" + std::to_string(s), "expected a length > 0 m");
    hose.expansionCoefficient = r.number(r.member(value, at, "expansionCoefficient"),
                                         at + "/expansionCoefficient", 0.0, 0.999999, "[0, 1)");
    const Json& limit = r.object(r.member(value, at, "bendLimit"), at + "/bendLimit");
    if (limit.contains("minBendRadius") == limit.contains("deflectionAngle") || limit.size() != 1)
        r.fail(at + "/bendLimit",
               "expected exactly one of minBendRadius (m), deflectionAngle (rad)");
    if (limit.contains("minBendRadius"))
        hose.bendLimit = BendLimit::minBendRadius(r.number(
            limit["minBendRadius"], at + "/bendLimit/minBendRadius", 0.0, 1e300, "[0, ∞)"));
    else
        hose.bendLimit = BendLimit::deflectionAngle(r.number(limit["deflectionAngle"],
                                                             at + "/bendLimit/deflectionAngle", 0.0,
                                                             3.14159265358979, "[0, π)"));
    hose.jointBendLimits =
        r.numbers(r.member(value, at, "jointBendLimits"), at + "/jointBendLimits");
    hose.jointMinBendRadii =
        r.numbers(r.member(value, at, "jointMinBendRadii"), at + "/jointMinBendRadii");
    const size_t interior = axis.size() - 2;
    if (hose.jointBendLimits.size() != interior)
        r.fail(at + "/jointBendLimits",
               "expected " + std::to_string(interior) + " interior-joint limits (points − 2)");
    if (hose.jointMinBendRadii.size() != interior)
        r.fail(at + "/jointMinBendRadii",
               "expected " + std::to_string(interior) + " interior-joint radii (points − 2)");
    hose.outerDiameter = r.number(r.member(value, at, "outerDiameter"), at + "/outerDiameter",
                                  1e-300, 1e300, "(0, ∞)");
    const Json& section = r.object(r.member(value, at, "crossSection"), at + "/crossSection");
    hose.crossSection.shape = shapeOf(
        r.string(r.member(section, at + "/crossSection", "shape"), at + "/crossSection/shape"), r,
        at + "/crossSection/shape");
    hose.crossSection.parameters = r.numbers(r.member(section, at + "/crossSection", "parameters"),
                                             at + "/crossSection/parameters");
    if (hose.crossSection.parameters.size() != parameterCount(hose.crossSection.shape))
        r.fail(at + "/crossSection/parameters",
               "expected " + std::to_string(parameterCount(hose.crossSection.shape)) +
                   " parameters for shape " + shapeName(hose.crossSection.shape));
    if (hose.crossSection.shape == Profile::Shape::Polygon) {
        const Json& outline =
            r.array(r.member(section, at + "/crossSection", "points"), at + "/crossSection/points");
        for (size_t i = 0; i < outline.size(); ++i) {
            const std::string p = at + "/crossSection/points/" + std::to_string(i);
            r.array(outline[i], p);
            if (outline[i].size() != 2) r.fail(p, "expected 2 numbers [x, y]");
            hose.crossSection.polygonPoints.emplace_back(r.number(outline[i][0], p + "/0"),
                                                         r.number(outline[i][1], p + "/1"));
        }
    }
    try {
        static_cast<void>(hose.crossSection.build());
    } catch (const InvalidArgument& error) {
        r.fail(at + "/crossSection", error.what());
    }
    std::vector<int> owner(axis.size(), -1);
    const Json& attachments = r.array(r.member(value, at, "attachments"), at + "/attachments");
    for (size_t k = 0; k < attachments.size(); ++k) {
        const std::string p = at + "/attachments/" + std::to_string(k);
        const Json& a = r.object(attachments[k], p);
        RigAttachment attachment;
        attachment.node = r.integer(r.member(a, p, "node"), p + "/node", -1);
        attachment.offset = r.frame(r.member(a, p, "offset"), p + "/offset");
        attachment.frame = r.frame(r.member(a, p, "frame"), p + "/frame");
        const std::vector<int> range = r.integers(r.member(a, p, "points"), p + "/points", 0);
        if (range.size() != 2 || range[0] > range[1] || range[1] >= points)
            r.fail(p + "/points",
                   "expected [first, last] with 0 ≤ first ≤ last < " + std::to_string(points));
        attachment.firstPoint = range[0];
        attachment.lastPoint = range[1];
        for (int i = range[0]; i <= range[1]; ++i) {
            if (owner[static_cast<size_t>(i)] >= 0)
                r.fail(p + "/points", "overlaps attachment " +
                                          std::to_string(owner[static_cast<size_t>(i)]) +
                                          " at point " + std::to_string(i));
            owner[static_cast<size_t>(i)] = static_cast<int>(k);
        }
        hose.attachments.push_back(attachment);
    }
    if (value.contains("clips")) { // 1.4
        // Each clip where rebuildHose() can add it (Hose::addClip's rule): its place on the
        // hose within its end stops, on a segment of non-zero length whose points no attachment
        // or earlier clip fixes.
        std::vector<double> prefix(axis.size(), 0.0);
        for (size_t s = 0; s + 1 < axis.size(); ++s)
            prefix[s + 1] = prefix[s] + hose.restLengths[s];
        const Json& clips = r.array(value["clips"], at + "/clips");
        for (size_t k = 0; k < clips.size(); ++k) {
            const std::string p = at + "/clips/" + std::to_string(k);
            const Json& c = r.object(clips[k], p);
            r.onlyKeys(c, p, {"node", "offset", "frame", "place", "hold", "slideMin", "slideMax"});
            RigClip clip;
            clip.node = r.integer(r.member(c, p, "node"), p + "/node", -1);
            clip.offset = r.frame(r.member(c, p, "offset"), p + "/offset");
            clip.frame = r.frame(r.member(c, p, "frame"), p + "/frame");
            const std::string hold = r.string(r.member(c, p, "hold"), p + "/hold");
            if (hold == toString(Hold::Sliding))
                clip.hold = Hold::Sliding;
            else if (hold == toString(Hold::SlidingTurning))
                clip.hold = Hold::SlidingTurning;
            else
                r.fail(p + "/hold", "expected \"sliding\" or \"sliding-turning\"");
            const double total = prefix.back();
            clip.slideMin = r.number(r.member(c, p, "slideMin"), p + "/slideMin", 0.0, total,
                                     "[0, the hose's rest length]");
            if (c.contains("slideMax"))
                clip.slideMax =
                    r.number(c["slideMax"], p + "/slideMax", clip.slideMin, HUGE_VAL, "≥ slideMin");
            clip.place = r.number(r.member(c, p, "place"), p + "/place", clip.slideMin,
                                  std::min(total, clip.slideMax),
                                  "within the end stops and the hose's rest length");
            const int segments = static_cast<int>(axis.size()) - 1;
            int j = std::clamp(
                static_cast<int>(std::upper_bound(prefix.begin(), prefix.end(), clip.place) -
                                 prefix.begin()) -
                    1,
                0, segments - 1);
            auto taken = [&](int i) { return owner[static_cast<size_t>(i)] != -1; };
            if (clip.place == prefix[static_cast<size_t>(j)] && j > 0 && (taken(j) || taken(j + 1)))
                --j;
            for (const int i : {j, j + 1})
                if (taken(i))
                    r.fail(p + "/place", "the segment holding the clip has point " +
                                             std::to_string(i) +
                                             " fixed by an attachment or an earlier clip");
            if (!((hose.axis[static_cast<size_t>(j) + 1] - hose.axis[static_cast<size_t>(j)])
                      .norm() > 0.0))
                r.fail(p + "/place", "the segment holding the clip has zero length");
            owner[static_cast<size_t>(j)] = owner[static_cast<size_t>(j) + 1] = -2;
            hose.clips.push_back(clip);
        }
    }
    hose.grabbablePoints =
        r.integers(r.member(value, at, "grabbablePoints"), at + "/grabbablePoints", 0);
    for (size_t i = 0; i < hose.grabbablePoints.size(); ++i) {
        const int point = hose.grabbablePoints[i];
        const std::string p = at + "/grabbablePoints/" + std::to_string(i);
        if (point >= points) r.fail(p, "expected a point index < " + std::to_string(points));
        if (owner[static_cast<size_t>(point)] >= 0)
            r.fail(p, "point " + std::to_string(point) + " is fixed by attachment " +
                          std::to_string(owner[static_cast<size_t>(point)]) +
                          " and cannot be grabbed");
        if (i > 0 && point <= hose.grabbablePoints[i - 1]) r.fail(p, "expected ascending indices");
    }
    if (hose.isStatic) {
        if (hose.skin != -1 || hose.rigNode != -1 || !hose.jointNodes.empty())
            r.fail(at + (hose.skin != -1      ? "/skin"
                         : hose.rigNode != -1 ? "/rig"
                                              : "/joints"),
                   "a static hose is a plain mesh: expected skin -1, rig -1 and no joints");
        if (!hose.grabbablePoints.empty() || hose.attachments.empty() ||
            std::count(owner.begin(), owner.end(), -1) > 0)
            r.fail(at + "/static", "expected every axis point fixed by an attachment (a static "
                                   "hose has no free points)");
        for (size_t k = 1; k < hose.attachments.size(); ++k)
            if (hose.attachments[k].node != hose.attachments[0].node)
                r.fail(at + "/attachments/" + std::to_string(k) + "/node",
                       "a static hose is fixed to one node: expected node " +
                           std::to_string(hose.attachments[0].node));
    }
    const Json& material = r.object(r.member(value, at, "material"), at + "/material");
    const Json& colour = r.array(r.member(material, at + "/material", "baseColorFactor"),
                                 at + "/material/baseColorFactor");
    if (colour.size() != 4)
        r.fail(at + "/material/baseColorFactor", "expected 4 numbers [r, g, b, a]");
    for (size_t c = 0; c < 4; ++c)
        hose.baseColour[c] = r.number(
            colour[c], at + "/material/baseColorFactor/" + std::to_string(c), 0.0, 1.0, "[0, 1]");
    hose.roughness = r.number(r.member(material, at + "/material", "roughness"),
                              at + "/material/roughness", 0.0, 1.0, "[0, 1]");
    if (value.contains("gravity")) {
        const std::string p = at + "/gravity";
        const Json& gravity = r.object(value["gravity"], p);
        hose.gravity.enabled = r.boolean(r.member(gravity, p, "enabled"), p + "/enabled");
        hose.gravity.direction = r.vector3(r.member(gravity, p, "direction"), p + "/direction");
        if (hose.gravity.direction.squaredNorm() == 0.0)
            r.fail(p + "/direction", "expected a non-zero vector (world, need not be unit)");
        r.onlyKeys(gravity, p, {"enabled", "direction"});
    }
    if (value.contains("torsion")) {
        const std::string p = at + "/torsion";
        const Json& torsion = r.object(value["torsion"], p);
        hose.torsion.enabled = r.boolean(r.member(torsion, p, "enabled"), p + "/enabled");
        hose.torsion.twistLimit = r.number(r.member(torsion, p, "twistLimit"), p + "/twistLimit");
        if (!(hose.torsion.twistLimit > 0.0 && hose.torsion.twistLimit <= 3.141592653589793))
            r.fail(p + "/twistLimit", "expected an angle in (0, π] rad per joint, got " +
                                          torsion["twistLimit"].dump());
        r.onlyKeys(torsion, p, {"enabled", "twistLimit"});
    }
    if (value.contains("plugs")) { // 1.5
        const std::string p = at + "/plugs";
        const Json& plugs = r.object(value["plugs"], p);
        r.onlyKeys(plugs, p, {"start", "end"});
        if (plugs.contains("start")) hose.plugStart = r.string(plugs["start"], p + "/start");
        if (plugs.contains("end")) hose.plugEnd = r.string(plugs["end"], p + "/end");
    }
    return hose;
}

} // namespace

const char* motionKindName(RigMotion::Kind kind)
{
    return kind == RigMotion::Kind::Hinge ? "hinge" : "slider";
}

const char* shapeName(Profile::Shape shape)
{
    switch (shape) {
    case Profile::Shape::Circle:
        return "circle";
    case Profile::Shape::Ellipse:
        return "ellipse";
    case Profile::Shape::Rectangle:
        return "rectangle";
    case Profile::Shape::RoundedRectangle:
        return "roundedRectangle";
    case Profile::Shape::Polygon:
        return "polygon";
    }
    return "circle";
}

CrossSection CrossSection::of(const Profile& profile)
{
    CrossSection section;
    section.shape = profile.shape();
    section.parameters = profile.parameters();
    section.polygonPoints = profile.polygonPoints();
    return section;
}

Profile CrossSection::build() const
{
    const std::vector<double>& p = parameters;
    if (p.size() != parameterCount(shape))
        throw InvalidArgument(std::string("crossSection.parameters: expected ") +
                              std::to_string(parameterCount(shape)) + " values for " +
                              shapeName(shape));
    switch (shape) {
    case Profile::Shape::Circle:
        return Profile::circle(p[0], static_cast<int>(p[1]));
    case Profile::Shape::Ellipse:
        return Profile::ellipse(p[0], p[1], static_cast<int>(p[2]));
    case Profile::Shape::Rectangle:
        return Profile::rectangle(p[0], p[1]);
    case Profile::Shape::RoundedRectangle:
        return Profile::roundedRectangle(p[0], p[1], p[2], static_cast<int>(p[3]));
    case Profile::Shape::Polygon:
        return Profile::polygon(polygonPoints, p[0]);
    }
    throw InvalidArgument("crossSection.shape: unknown shape");
}

Material RigHose::material() const
{
    Material result;
    result.expansionCoefficient = expansionCoefficient;
    result.bendLimit = bendLimit;
    return result;
}

std::string serialiseDescriptor(const HoseRigDescriptor& descriptor)
{
    Json document;
    document["format"] = kDescriptorFormat;
    document["version"] = descriptor.version;
    document["generator"] = descriptor.generator;
    document["units"] = Json{{"length", "metre"}, {"angle", "radian"}};
    Json hoses = Json::array();
    for (const RigHose& hose : descriptor.hoses) {
        Json h;
        h["id"] = hose.id;
        h["name"] = hose.name;
        h["static"] = hose.isStatic;
        h["mesh"] = hose.meshNode;
        h["skin"] = hose.skin;
        h["rig"] = hose.rigNode;
        h["joints"] = list(hose.jointNodes);
        Json axis = Json::array();
        for (const Vec3& point : hose.axis)
            axis.push_back(vec3(point));
        h["axis"] = axis;
        h["restLengths"] = list(hose.restLengths);
        h["expansionCoefficient"] = hose.expansionCoefficient;
        if (hose.bendLimit.kind == BendLimit::Kind::MinBendRadius)
            h["bendLimit"] = Json{{"minBendRadius", hose.bendLimit.value}};
        else
            h["bendLimit"] = Json{{"deflectionAngle", hose.bendLimit.value}};
        h["jointBendLimits"] = list(hose.jointBendLimits);
        h["jointMinBendRadii"] = list(hose.jointMinBendRadii);
        h["outerDiameter"] = hose.outerDiameter;
        h["radius"] = 0.5 * hose.outerDiameter;
        Json section{{"shape", shapeName(hose.crossSection.shape)},
                     {"parameters", list(hose.crossSection.parameters)}};
        if (hose.crossSection.shape == Profile::Shape::Polygon) {
            Json outline = Json::array();
            for (const Vec2& point : hose.crossSection.polygonPoints)
                outline.push_back(Json::array({point.x(), point.y()}));
            section["points"] = outline;
        }
        h["crossSection"] = section;
        Json attachments = Json::array();
        for (const RigAttachment& attachment : hose.attachments)
            attachments.push_back(
                Json{{"node", attachment.node},
                     {"offset", frame(attachment.offset)},
                     {"frame", frame(attachment.frame)},
                     {"points", Json::array({attachment.firstPoint, attachment.lastPoint})}});
        h["attachments"] = attachments;
        if (!hose.clips.empty()) { // 1.4
            Json clips = Json::array();
            for (const RigClip& clip : hose.clips) {
                Json c{{"node", clip.node},           {"offset", frame(clip.offset)},
                       {"frame", frame(clip.frame)},  {"place", clip.place},
                       {"hold", toString(clip.hold)}, {"slideMin", clip.slideMin}};
                if (std::isfinite(clip.slideMax)) c["slideMax"] = clip.slideMax;
                clips.push_back(c);
            }
            h["clips"] = clips;
        }
        h["grabbablePoints"] = list(hose.grabbablePoints);
        h["material"] =
            Json{{"baseColorFactor", Json::array({hose.baseColour[0], hose.baseColour[1],
                                                  hose.baseColour[2], hose.baseColour[3]})},
                 {"roughness", hose.roughness}};
        h["gravity"] =
            Json{{"enabled", hose.gravity.enabled}, {"direction", vec3(hose.gravity.direction)}};
        h["torsion"] =
            Json{{"enabled", hose.torsion.enabled}, {"twistLimit", hose.torsion.twistLimit}};
        if (!hose.plugStart.empty() || !hose.plugEnd.empty()) { // 1.5
            Json plugs = Json::object();
            if (!hose.plugStart.empty()) plugs["start"] = hose.plugStart;
            if (!hose.plugEnd.empty()) plugs["end"] = hose.plugEnd;
            h["plugs"] = plugs;
        }
        hoses.push_back(h);
    }
    document["hoses"] = hoses;
    document["colliders"] = list(descriptor.colliders);
    Json motions = Json::array();
    for (const RigMotion& motion : descriptor.motions) {
        Json m{{"id", motion.id},
               {"node", motion.node},
               {"kind", motionKindName(motion.kind)},
               {"axis", vec3(motion.axis)},
               {"min", motion.minimum},
               {"max", motion.maximum}};
        if (motion.kind == RigMotion::Kind::Hinge) m["point"] = vec3(motion.point);
        motions.push_back(m);
    }
    document["motions"] = motions;
    Json sockets = Json::array();
    for (const RigSocket& socket : descriptor.sockets)
        sockets.push_back(Json{{"id", socket.id},
                               {"node", socket.node},
                               {"nodeName", socket.nodeName},
                               {"position", vec3(socket.position)},
                               {"axis", vec3(socket.axis)},
                               {"worldPosition", vec3(socket.worldPosition)},
                               {"worldAxis", vec3(socket.worldAxis)},
                               {"captureRadius", socket.captureRadius},
                               {"captureAngle", socket.captureAngle},
                               {"tag", socket.tag}});
    document["sockets"] = sockets;
    return document.dump(2) + "\n";
}

HoseRigDescriptor parseDescriptor(std::string_view text, const std::string& source)
{
    const Reader r(source);
    Json document;
    try {
        document = Json::parse(text.begin(), text.end());
    } catch (const nlohmann::json::exception& error) { // parse_error, or out_of_range for 1e400
        r.fail("", std::string("malformed JSON: ") + error.what());
    }
    r.object(document, "");
    if (r.string(r.member(document, "", "format"), "/format") != kDescriptorFormat)
        r.fail("/format", std::string("expected \"") + kDescriptorFormat + "\"");
    HoseRigDescriptor descriptor;
    descriptor.version = r.string(r.member(document, "", "version"), "/version");
    int major = 0, minor = 0;
    if (std::sscanf(descriptor.version.c_str(), "%d.%d", &major, &minor) != 2)
        r.fail("/version", "expected \"major.minor\", got \"" + descriptor.version + "\"");
    if (major > kDescriptorMajor)
        r.fail("/version", "version " + descriptor.version + " is newer than this reader (" +
                               std::to_string(kDescriptorMajor) + ".x)");
    if (document.contains("generator"))
        descriptor.generator = r.string(document["generator"], "/generator");
    const Json& units = r.object(r.member(document, "", "units"), "/units");
    if (units.value("length", "") != "metre" || units.value("angle", "") != "radian")
        r.fail("/units", "expected {\"length\": \"metre\", \"angle\": \"radian\"}");
    if (document.contains("colliders")) {
        descriptor.colliders = r.integers(document["colliders"], "/colliders", 0);
        for (size_t i = 1; i < descriptor.colliders.size(); ++i)
            if (descriptor.colliders[i] <= descriptor.colliders[i - 1])
                r.fail("/colliders/" + std::to_string(i), "expected ascending node indices");
    }
    if (document.contains("motions")) {
        const Json& motions = r.array(document["motions"], "/motions");
        std::set<std::string> motionIds;
        for (size_t i = 0; i < motions.size(); ++i)
            descriptor.motions.push_back(
                readMotion(motions[i], "/motions/" + std::to_string(i), r));
        for (size_t i = 0; i < descriptor.motions.size(); ++i)
            if (!motionIds.insert(descriptor.motions[i].id).second)
                r.fail("/motions/" + std::to_string(i) + "/id",
                       "duplicate motion id \"" + descriptor.motions[i].id + "\"");
    }
    if (document.contains("sockets")) { // 1.5
        const Json& sockets = r.array(document["sockets"], "/sockets");
        std::set<std::string> socketIds;
        for (size_t i = 0; i < sockets.size(); ++i) {
            const std::string at = "/sockets/" + std::to_string(i);
            descriptor.sockets.push_back(readSocket(sockets[i], at, r));
            if (!socketIds.insert(descriptor.sockets.back().id).second)
                r.fail(at + "/id", "duplicate socket id \"" + descriptor.sockets.back().id + "\"");
        }
    }
    const Json& hoses = r.array(r.member(document, "", "hoses"), "/hoses");
    std::set<std::string> ids;
    for (size_t i = 0; i < hoses.size(); ++i) {
        const std::string at = "/hoses/" + std::to_string(i);
        descriptor.hoses.push_back(readHose(hoses[i], at, r));
        if (!ids.insert(descriptor.hoses.back().id).second)
            r.fail(at + "/id", "duplicate hose id \"" + descriptor.hoses.back().id + "\"");
    }
    return descriptor;
}

Hose rebuildHose(const RigHose& description, std::vector<int>* attachmentIds)
{
    HoseSpec spec;
    spec.outerDiameter = description.outerDiameter;
    spec.material = description.material();
    spec.segmentCount = description.pointCount() - 1;
    spec.profile = description.crossSection.build();
    spec.gravity = description.gravity;
    spec.torsion = description.torsion;
    // The exported shape with the exported rest lengths: a hose exported while deformed comes
    // back deformed, not relaxed at that shape.
    Hose hose = description.restLengths.size() + 1 == description.axis.size()
                    ? Hose::fromAxis(description.axis, description.restLengths, spec)
                    : Hose::fromAxis(description.axis, spec);
    for (const RigAttachment& attachment : description.attachments) {
        const int id = hose.attach(attachment.firstPoint, attachment.lastPoint, attachment.frame);
        if (attachmentIds) attachmentIds->push_back(id);
    }
    for (const RigClip& clip : description.clips) {
        const int id =
            hose.addClip(clip.place, clip.frame, {clip.hold, clip.slideMin, clip.slideMax});
        if (attachmentIds) attachmentIds->push_back(id);
    }
    return hose;
}

bool restLengthsMatch(const RigHose& hose)
{
    for (size_t s = 0; s + 1 < hose.axis.size(); ++s) {
        const double length = (hose.axis[s + 1] - hose.axis[s]).norm();
        if (s >= hose.restLengths.size() ||
            std::abs(length - hose.restLengths[s]) > 1e-9 * hose.restLengths[s])
            return false;
    }
    return true;
}

bool withinStretchBand(const RigHose& hose)
{
    const double band = hose.expansionCoefficient;
    for (size_t s = 0; s + 1 < hose.axis.size(); ++s) {
        if (s >= hose.restLengths.size()) return false;
        const double length = (hose.axis[s + 1] - hose.axis[s]).norm();
        const double rest = hose.restLengths[s];
        if (length > rest * (1.0 + band) * (1.0 + 1e-9) ||
            length < rest * (1.0 - band) * (1.0 - 1e-9))
            return false;
    }
    return true;
}

std::vector<std::string> checkAgainstGltf(const HoseRigDescriptor& descriptor, int nodeCount,
                                          int skinCount)
{
    std::vector<std::string> problems;
    std::set<int> usedJoints;
    const auto node = [&](int index, const std::string& pointer, bool allowNone) {
        if (index == -1 && allowNone) return;
        if (index < 0 || index >= nodeCount)
            problems.push_back(pointer + ": node " + std::to_string(index) +
                               " is not a node of the glTF (" + std::to_string(nodeCount) +
                               " nodes)");
    };
    for (size_t h = 0; h < descriptor.hoses.size(); ++h) {
        const RigHose& hose = descriptor.hoses[h];
        const std::string at = "/hoses/" + std::to_string(h);
        const bool skinned = hose.skin >= 0;
        node(hose.meshNode, at + "/mesh", false);
        node(hose.rigNode, at + "/rig", !skinned);
        if (hose.skin >= skinCount)
            problems.push_back(at + "/skin: skin " + std::to_string(hose.skin) +
                               " is not a skin of the glTF");
        for (size_t j = 0; j < hose.jointNodes.size(); ++j) {
            node(hose.jointNodes[j], at + "/joints/" + std::to_string(j), false);
            if (!usedJoints.insert(hose.jointNodes[j]).second)
                problems.push_back(at + "/joints/" + std::to_string(j) + ": node " +
                                   std::to_string(hose.jointNodes[j]) +
                                   " is already the joint of another axis point");
        }
        for (size_t k = 0; k < hose.attachments.size(); ++k)
            node(hose.attachments[k].node, at + "/attachments/" + std::to_string(k) + "/node",
                 true);
        for (size_t k = 0; k < hose.clips.size(); ++k)
            node(hose.clips[k].node, at + "/clips/" + std::to_string(k) + "/node", true);
    }
    for (size_t c = 0; c < descriptor.colliders.size(); ++c)
        node(descriptor.colliders[c], "/colliders/" + std::to_string(c), false);
    for (size_t m = 0; m < descriptor.motions.size(); ++m)
        node(descriptor.motions[m].node, "/motions/" + std::to_string(m) + "/node", false);
    for (size_t k = 0; k < descriptor.sockets.size(); ++k)
        node(descriptor.sockets[k].node, "/sockets/" + std::to_string(k) + "/node", true);
    return problems;
}

} // namespace chaintube::rig
