#include "chaintube/formats/project.h"

#include <cmath>
#include <utility>

namespace chaintube::formats {

std::vector<MaterialPreset> standardMaterialPresets()
{
    // Typical datasheet values for hoses of ~20 mm outer diameter: the minimum bend radius is
    // the centreline radius a manufacturer allows; expansion is how far the model may stretch
    // a segment (a visual tolerance, not a physical strain).
    return {
        {"PVC hose", "Clear PVC suction/delivery hose with textile braid, 19 mm ID",
         Material{0.05, BendLimit{BendLimit::Kind::MinBendRadius, 0.10}}},
        {"rubber hose", "EPDM coolant/air hose, 20 mm ID",
         Material{0.08, BendLimit{BendLimit::Kind::MinBendRadius, 0.12}}},
        {"braided steel hose", "PTFE hose with stainless-steel overbraid, -12 (19 mm)",
         Material{0.01, BendLimit{BendLimit::Kind::MinBendRadius, 0.165}}},
        {"cable bundle", "Wire harness bundle in corrugated sleeve, 20 mm",
         Material{0.02, BendLimit{BendLimit::Kind::MinBendRadius, 0.08}}},
    };
}

bool ProfileSpec::operator==(const ProfileSpec& o) const
{
    if (shape != o.shape) return false;
    switch (shape) {
    case Profile::Shape::Circle:
        return sides == o.sides;
    case Profile::Shape::Ellipse:
        return semiAxisX == o.semiAxisX && semiAxisY == o.semiAxisY && sides == o.sides;
    case Profile::Shape::Rectangle:
        return width == o.width && height == o.height;
    case Profile::Shape::RoundedRectangle:
        return width == o.width && height == o.height && cornerRadius == o.cornerRadius &&
               cornerSegments == o.cornerSegments;
    case Profile::Shape::Polygon:
        return points == o.points && smoothAngle == o.smoothAngle;
    }
    return false;
}

bool HoseAttachment::operator==(const HoseAttachment& o) const
{
    return scene == o.scene && node == o.node && offset.translation == o.offset.translation &&
           offset.rotation.coeffs() == o.offset.rotation.coeffs() && firstPoint == o.firstPoint &&
           lastPoint == o.lastPoint;
}

bool HoseClip::operator==(const HoseClip& o) const
{
    return scene == o.scene && node == o.node && offset.translation == o.offset.translation &&
           offset.rotation.coeffs() == o.offset.rotation.coeffs() && place == o.place &&
           hold == o.hold && slideMin == o.slideMin && slideMax == o.slideMax;
}

bool HoseDefinition::operator==(const HoseDefinition& o) const
{
    const bool sameResolution =
        segmentCount == o.segmentCount && (segmentCount > 0 || segmentLength == o.segmentLength);
    return id == o.id && name == o.name && route == o.route && length == o.length &&
           material == o.material && profile == o.profile && outerDiameter == o.outerDiameter &&
           sameResolution && colour == o.colour && roughness == o.roughness &&
           attachments == o.attachments && clips == o.clips &&
           gravity.enabled == o.gravity.enabled && gravity.direction == o.gravity.direction &&
           torsion.enabled == o.torsion.enabled && torsion.twistLimit == o.torsion.twistLimit &&
           fittingsAllowance == o.fittingsAllowance && plugs == o.plugs;
}

bool Socket::operator==(const Socket& o) const
{
    return id == o.id && scene == o.scene && node == o.node && position == o.position &&
           axis == o.axis && captureRadius == o.captureRadius && captureAngle == o.captureAngle &&
           tag == o.tag;
}

bool PartMotion::operator==(const PartMotion& o) const
{
    return id == o.id && scene == o.scene && node == o.node && kind == o.kind && axis == o.axis &&
           (kind != Kind::Hinge || point == o.point) && minimum == o.minimum &&
           maximum == o.maximum;
}

const char* toString(PartMotion::Kind kind)
{
    return kind == PartMotion::Kind::Hinge ? "hinge" : "slider";
}

Project Project::withStandardPresets(std::string name)
{
    Project project;
    project.name = std::move(name);
    project.materialPresets = standardMaterialPresets();
    return project;
}

const MaterialPreset* Project::findPreset(std::string_view presetName) const
{
    for (const MaterialPreset& preset : materialPresets)
        if (preset.name == presetName) return &preset;
    return nullptr;
}

const SceneReference* Project::findScene(std::string_view sceneId) const
{
    for (const SceneReference& scene : scenes)
        if (scene.id == sceneId) return &scene;
    return nullptr;
}

const Socket* Project::findSocket(std::string_view socketId) const
{
    for (const Socket& socket : sockets)
        if (socket.id == socketId) return &socket;
    return nullptr;
}

Material Project::materialOf(const HoseDefinition& hose) const
{
    if (const auto* inlineMaterial = std::get_if<Material>(&hose.material)) return *inlineMaterial;
    const std::string& presetName = std::get<PresetName>(hose.material).name;
    const MaterialPreset* preset = findPreset(presetName);
    if (!preset)
        throw InvalidArgument("hose '" + hose.id + "': unknown material preset '" + presetName +
                              "'");
    return preset->material;
}

bool Project::operator==(const Project& o) const
{
    return name == o.name && scenes == o.scenes && materialPresets == o.materialPresets &&
           hoses == o.hoses && poses == o.poses && colliders == o.colliders &&
           motions == o.motions && checks == o.checks && sockets == o.sockets &&
           exportSettings == o.exportSettings;
}

std::filesystem::path resolveScenePath(const SceneReference& scene,
                                       const std::filesystem::path& projectFile,
                                       const NamedRoots& roots)
{
    return resolveProjectPath(scene.path, std::filesystem::absolute(projectFile).parent_path(),
                              roots);
}

Project rebaseProject(Project project, const std::filesystem::path& fromFile,
                      const std::filesystem::path& toFile)
{
    const std::filesystem::path from = std::filesystem::absolute(fromFile).parent_path();
    const std::filesystem::path to = std::filesystem::absolute(toFile).parent_path();
    for (SceneReference& scene : project.scenes)
        scene.path = rebaseProjectPath(scene.path, from, to);
    if (!project.exportSettings.path.empty())
        project.exportSettings.path = rebaseProjectPath(project.exportSettings.path, from, to);
    return project;
}

} // namespace chaintube::formats
