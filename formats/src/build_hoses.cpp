#include "chaintube/formats/project_hoses.h"

namespace chaintube::formats {

namespace {

Profile profileOf(const HoseDefinition& hose)
{
    const ProfileSpec& p = hose.profile;
    switch (p.shape) {
    case Profile::Shape::Circle:
        return Profile::circle(0.5 * hose.outerDiameter, p.sides);
    case Profile::Shape::Ellipse:
        return Profile::ellipse(p.semiAxisX, p.semiAxisY, p.sides);
    case Profile::Shape::Rectangle:
        return Profile::rectangle(p.width, p.height);
    case Profile::Shape::RoundedRectangle:
        return Profile::roundedRectangle(p.width, p.height, p.cornerRadius, p.cornerSegments);
    case Profile::Shape::Polygon:
        return Profile::polygon(p.points, p.smoothAngle);
    }
    throw InvalidArgument("hose '" + hose.id + "': unknown profile shape");
}

} // namespace

ImportedScenes importProjectScenes(const Project& project, const std::filesystem::path& projectFile,
                                   const NamedRoots& roots,
                                   const std::function<bool(double)>& progress)
{
    ImportedScenes scenes;
    const double count = static_cast<double>(project.scenes.size());
    for (size_t i = 0; i < project.scenes.size(); ++i) {
        const SceneReference& reference = project.scenes[i];
        ImportOptions options;
        options.metresPerUnit = reference.import.metresPerUnit;
        options.upAxis = reference.import.upAxis;
        options.chordalTolerance = reference.import.chordalTolerance;
        options.angularTolerance = reference.import.angularTolerance;
        if (progress)
            options.progress = [&](double fraction) {
                return progress((static_cast<double>(i) + fraction) / count);
            };
        scenes.emplace(reference.id,
                       importScene(resolveScenePath(reference, projectFile, roots), options));
    }
    return scenes;
}

HoseSpec hoseSpecOf(const Project& project, const HoseDefinition& hose)
{
    HoseSpec spec;
    spec.outerDiameter = hose.outerDiameter;
    spec.material = project.materialOf(hose);
    spec.segmentCount = hose.segmentCount;
    spec.segmentLength = hose.segmentLength;
    spec.profile = profileOf(hose);
    return spec;
}

Hose buildHose(const Project& project, const HoseDefinition& definition,
               const ImportedScenes& scenes)
{
    Hose hose = Hose::alongRoute(definition.route, hoseSpecOf(project, definition));
    for (const HoseAttachment& attachment : definition.attachments) {
        const auto scene = scenes.find(attachment.scene);
        if (scene == scenes.end())
            throw InvalidArgument("hose '" + definition.id + "': scene '" + attachment.scene +
                                  "' is not imported");
        const int node = scene->second.findNode(attachment.node);
        if (node < 0)
            throw InvalidArgument("hose '" + definition.id + "': scene '" + attachment.scene +
                                  "' has no node '" + attachment.node + "'");
        if (attachment.lastPoint >= hose.pointCount())
            throw InvalidArgument("hose '" + definition.id + "': attachment points [" +
                                  std::to_string(attachment.firstPoint) + ", " +
                                  std::to_string(attachment.lastPoint) + "] outside the hose's " +
                                  std::to_string(hose.pointCount()) + " axis points");
        Frame offset = attachment.offset;
        offset.rotation.normalize();
        hose.attach(attachment.firstPoint, attachment.lastPoint,
                    scene->second.worldFrame(node) * offset);
    }
    return hose;
}

std::vector<Hose> buildHoses(const Project& project, const ImportedScenes& scenes)
{
    std::vector<Hose> hoses;
    hoses.reserve(project.hoses.size());
    for (const HoseDefinition& definition : project.hoses)
        hoses.push_back(buildHose(project, definition, scenes));
    return hoses;
}

} // namespace chaintube::formats
