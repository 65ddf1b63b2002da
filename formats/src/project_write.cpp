// Writing *.ctproj in canonical form.
#include "chaintube/formats/project.h"

#include <nlohmann/json.hpp>

namespace chaintube::formats {

using ordered = nlohmann::ordered_json;

namespace {

ordered vec3(const Vec3& v)
{
    return ordered::array({v.x(), v.y(), v.z()});
}

ordered materialValues(const Material& material)
{
    ordered out = ordered::object();
    out["expansionCoefficient"] = material.expansionCoefficient;
    ordered limit = ordered::object();
    if (material.bendLimit.kind == BendLimit::Kind::MinBendRadius)
        limit["minBendRadius"] = material.bendLimit.value;
    else
        limit["deflectionAngle"] = material.bendLimit.value;
    out["bendLimit"] = limit;
    return out;
}

ordered profileJson(const ProfileSpec& profile)
{
    ordered out = ordered::object();
    switch (profile.shape) {
    case Profile::Shape::Circle:
        out["shape"] = "circle";
        out["sides"] = profile.sides;
        break;
    case Profile::Shape::Ellipse:
        out["shape"] = "ellipse";
        out["semiAxisX"] = profile.semiAxisX;
        out["semiAxisY"] = profile.semiAxisY;
        out["sides"] = profile.sides;
        break;
    case Profile::Shape::Rectangle:
        out["shape"] = "rectangle";
        out["width"] = profile.width;
        out["height"] = profile.height;
        break;
    case Profile::Shape::RoundedRectangle:
        out["shape"] = "roundedRectangle";
        out["width"] = profile.width;
        out["height"] = profile.height;
        out["cornerRadius"] = profile.cornerRadius;
        out["cornerSegments"] = profile.cornerSegments;
        break;
    case Profile::Shape::Polygon: {
        out["shape"] = "polygon";
        ordered points = ordered::array();
        for (const Vec2& p : profile.points)
            points.push_back(ordered::array({p.x(), p.y()}));
        out["points"] = points;
        out["smoothAngle"] = profile.smoothAngle;
        break;
    }
    }
    return out;
}

/// nlohmann writes arrays of numbers one element per line; route points and colours read
/// better on one line each, so short numeric arrays are collapsed after dumping.
std::string collapseShortNumericArrays(const std::string& text)
{
    std::string out;
    out.reserve(text.size());
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            out += c;
            if (c == '\\' && i + 1 < text.size())
                out += text[++i];
            else if (c == '"')
                inString = false;
            continue;
        }
        if (c == '"') {
            inString = true;
            out += c;
            continue;
        }
        if (c == '[') {
            // Only arrays holding numbers alone (no strings, arrays or objects) are collapsed.
            const size_t close = text.find(']', i);
            const size_t nested = text.find_first_of("[{\"", i + 1);
            if (close != std::string::npos && (nested == std::string::npos || nested > close)) {
                out += '[';
                for (size_t k = i + 1; k < close; ++k) {
                    if (text[k] == '\n' || text[k] == ' ') continue;
                    out += text[k];
                    if (text[k] == ',') out += ' ';
                }
                out += ']';
                i = close;
                continue;
            }
        }
        out += c;
    }
    return out;
}

} // namespace

std::string serialiseProject(const Project& project)
{
    ordered document = ordered::object();
    document["format"] = "chaintube-project";
    document["version"] =
        std::to_string(kProjectFormatMajor) + "." + std::to_string(kProjectFormatMinor);
    document["name"] = project.name;

    ordered scenes = ordered::array();
    for (const SceneReference& scene : project.scenes) {
        ordered entry = ordered::object();
        entry["id"] = scene.id;
        entry["path"] = scene.path;
        ordered import = ordered::object();
        if (scene.import.metresPerUnit) import["metresPerUnit"] = *scene.import.metresPerUnit;
        if (scene.import.upAxis)
            import["upAxis"] = *scene.import.upAxis == UpAxis::PositiveY ? "+Y" : "+Z";
        import["chordalTolerance"] = scene.import.chordalTolerance;
        import["angularTolerance"] = scene.import.angularTolerance;
        if (scene.import.placement != Vec3::Zero())
            import["placement"] = vec3(scene.import.placement);
        entry["import"] = import;
        scenes.push_back(entry);
    }
    document["scenes"] = scenes;

    ordered presets = ordered::array();
    for (const MaterialPreset& preset : project.materialPresets) {
        ordered entry = ordered::object();
        entry["name"] = preset.name;
        entry["description"] = preset.description;
        const ordered values = materialValues(preset.material);
        for (const auto& [key, value] : values.items())
            entry[key] = value;
        presets.push_back(entry);
    }
    document["materialPresets"] = presets;

    ordered hoses = ordered::array();
    for (const HoseDefinition& hose : project.hoses) {
        ordered entry = ordered::object();
        entry["id"] = hose.id;
        entry["name"] = hose.name;
        ordered route = ordered::array();
        for (const Vec3& point : hose.route)
            route.push_back(vec3(point));
        entry["route"] = route;
        if (hose.length) entry["length"] = *hose.length;
        if (const auto* preset = std::get_if<PresetName>(&hose.material))
            entry["material"] = preset->name;
        else
            entry["material"] = materialValues(std::get<Material>(hose.material));
        entry["profile"] = profileJson(hose.profile);
        entry["outerDiameter"] = hose.outerDiameter;
        if (hose.segmentCount > 0)
            entry["segmentCount"] = hose.segmentCount;
        else
            entry["segmentLength"] = hose.segmentLength;
        entry["colour"] =
            ordered::array({hose.colour.r, hose.colour.g, hose.colour.b, hose.colour.a});
        entry["roughness"] = hose.roughness;
        ordered attachments = ordered::array();
        for (const HoseAttachment& attachment : hose.attachments) {
            ordered item = ordered::object();
            item["scene"] = attachment.scene;
            item["node"] = attachment.node;
            const Quat& q = attachment.offset.rotation;
            item["offset"] = ordered{{"translation", vec3(attachment.offset.translation)},
                                     {"rotation", ordered::array({q.x(), q.y(), q.z(), q.w()})}};
            item["points"] = ordered::array({attachment.firstPoint, attachment.lastPoint});
            attachments.push_back(item);
        }
        entry["attachments"] = attachments;
        if (!hose.clips.empty()) { // 1.5
            ordered clips = ordered::array();
            for (const HoseClip& clip : hose.clips) {
                ordered item = ordered::object();
                item["scene"] = clip.scene;
                item["node"] = clip.node;
                const Quat& q = clip.offset.rotation;
                item["offset"] =
                    ordered{{"translation", vec3(clip.offset.translation)},
                            {"rotation", ordered::array({q.x(), q.y(), q.z(), q.w()})}};
                item["place"] = clip.place;
                item["hold"] = toString(clip.hold);
                if (clip.slideMin) item["slideMin"] = *clip.slideMin;
                if (clip.slideMax) item["slideMax"] = *clip.slideMax;
                clips.push_back(item);
            }
            entry["clips"] = clips;
        }
        // Written only when they differ from the defaults (off, straight down, 0.1 rad): most
        // hoses use neither, and the canonical file stays as short as before 1.2.
        const Gravity noGravity;
        if (hose.gravity.enabled != noGravity.enabled ||
            hose.gravity.direction != noGravity.direction)
            entry["gravity"] = ordered{{"enabled", hose.gravity.enabled},
                                       {"direction", vec3(hose.gravity.direction)}};
        const Torsion noTorsion;
        if (hose.torsion.enabled != noTorsion.enabled ||
            hose.torsion.twistLimit != noTorsion.twistLimit)
            entry["torsion"] =
                ordered{{"enabled", hose.torsion.enabled}, {"twistLimit", hose.torsion.twistLimit}};
        if (hose.fittingsAllowance != 0.0) // 1.6
            entry["fittingsAllowance"] = hose.fittingsAllowance;
        if (!hose.plugs.empty()) { // 1.7
            ordered plugs = ordered::object();
            if (!hose.plugs.start.empty()) plugs["start"] = hose.plugs.start;
            if (!hose.plugs.end.empty()) plugs["end"] = hose.plugs.end;
            entry["plugs"] = plugs;
        }
        hoses.push_back(entry);
    }
    document["hoses"] = hoses;

    ordered poses = ordered::array();
    for (const NodePose& pose : project.poses) {
        ordered matrix = ordered::array();
        for (int k = 0; k < 16; ++k) // column-major, as glTF
            matrix.push_back(pose.localTransform(k % 4, k / 4));
        poses.push_back(ordered{{"scene", pose.scene}, {"node", pose.node}, {"matrix", matrix}});
    }
    document["poses"] = poses;

    ordered colliders = ordered::array();
    for (const ColliderNode& collider : project.colliders)
        colliders.push_back(ordered{{"scene", collider.scene}, {"node", collider.node}});
    document["colliders"] = colliders;

    ordered motions = ordered::array();
    for (const PartMotion& motion : project.motions) {
        ordered entry = ordered::object();
        entry["id"] = motion.id;
        entry["scene"] = motion.scene;
        entry["node"] = motion.node;
        entry["kind"] = toString(motion.kind);
        entry["axis"] = vec3(motion.axis);
        if (motion.kind == PartMotion::Kind::Hinge) entry["point"] = vec3(motion.point);
        entry["min"] = motion.minimum;
        entry["max"] = motion.maximum;
        motions.push_back(entry);
    }
    document["motions"] = motions;

    if (project.checks.clearance) {
        ordered checks = ordered::object();
        checks["clearance"] = *project.checks.clearance;
        document["checks"] = checks;
    }

    if (!project.sockets.empty()) { // 1.7
        ordered sockets = ordered::array();
        for (const Socket& socket : project.sockets) {
            ordered entry = ordered::object();
            entry["id"] = socket.id;
            entry["scene"] = socket.scene;
            entry["node"] = socket.node;
            entry["position"] = vec3(socket.position);
            entry["axis"] = vec3(socket.axis);
            entry["captureRadius"] = socket.captureRadius;
            entry["captureAngle"] = socket.captureAngle;
            entry["tag"] = socket.tag;
            sockets.push_back(entry);
        }
        document["sockets"] = sockets;
    }

    ordered exportSettings = ordered::object();
    exportSettings["format"] = project.exportSettings.format;
    exportSettings["path"] = project.exportSettings.path;
    exportSettings["includeScene"] = project.exportSettings.includeScene;
    document["export"] = exportSettings;

    // Non-finite numbers would be written as null; validation in saveProject() refuses them.
    return collapseShortNumericArrays(document.dump(2)) + "\n";
}

void saveProject(const Project& project, const std::filesystem::path& file,
                 const ProjectLoadOptions& validation, const AtomicWriteOptions& write)
{
    const std::string text = serialiseProject(project);
    // Never write what we could not read back: the reader is the validator.
    const Project reread = parseProject(text, file, validation);
    if (reread != project)
        throw ProjectFormatError(file, "",
                                 "internal error: the project does not survive "
                                 "serialisation unchanged (non-finite value?)");
    writeFileAtomically(file, text, write);
}

} // namespace chaintube::formats
