#include "chaintube/editor/commands.h"

#include <QCoreApplication>
#include <algorithm>
#include <memory>

namespace chaintube::editor {

namespace {
QString tr(const char* text)
{
    return QCoreApplication::translate("Commands", text);
}

/// How the history names a hose: its name, or its id when it has none.
QString hoseLabel(const formats::HoseDefinition& definition)
{
    return QString::fromStdString(definition.name.empty() ? definition.id : definition.name);
}

QString nodeLabel(const Document& document, const NodeKey& node)
{
    const formats::ImportedScene* imported = document.scene(node.first);
    if (!imported || node.second < 0 || node.second >= static_cast<int>(imported->nodes.size()))
        return tr("part");
    return QString::fromStdString(imported->nodes[static_cast<size_t>(node.second)].name);
}
} // namespace

AddHoseCommand::AddHoseCommand(Document& document, formats::HoseDefinition definition)
    : QUndoCommand(tr("Add %1").arg(hoseLabel(definition))), m_document(document),
      m_definition(std::move(definition)), m_index(document.hoseCount())
{
}

void AddHoseCommand::redo()
{
    m_document.insertHose(m_index, m_definition);
}

void AddHoseCommand::undo()
{
    m_definition = m_document.removeHose(m_definition.id);
}

RemoveHoseCommand::RemoveHoseCommand(Document& document, std::string hoseId)
    : QUndoCommand(tr("Delete %1")
                       .arg(document.hoseDefinition(hoseId)
                                ? hoseLabel(*document.hoseDefinition(hoseId))
                                : QString::fromStdString(hoseId))),
      m_document(document), m_hoseId(std::move(hoseId))
{
}

void RemoveHoseCommand::redo()
{
    m_index = m_document.hoseIndex(m_hoseId);
    if (m_index >= 0) m_definition = m_document.removeHose(m_hoseId);
}

void RemoveHoseCommand::undo()
{
    if (m_index >= 0) m_document.insertHose(m_index, m_definition);
}

AddSceneCommand::AddSceneCommand(Document& document, formats::SceneReference reference,
                                 formats::ImportedScene scene)
    : QUndoCommand(tr("Import scene %1").arg(QString::fromStdString(reference.id))),
      m_document(document), m_reference(std::move(reference)), m_scene(std::move(scene))
{
}

void AddSceneCommand::redo()
{
    m_document.insertScene(static_cast<int>(m_document.project().scenes.size()), m_reference,
                           std::move(m_scene));
}

void AddSceneCommand::undo()
{
    auto removed = m_document.removeScene(m_reference.id);
    m_scene = std::move(removed.second);
}

RelinkSceneCommand::RelinkSceneCommand(Document& document, std::string sceneId, std::string newPath,
                                       formats::ImportedScene scene)
    : QUndoCommand(tr("Locate scene %1").arg(QString::fromStdString(sceneId))),
      m_document(document), m_sceneId(std::move(sceneId)), m_newPath(std::move(newPath)),
      m_held(std::move(scene))
{
    const formats::SceneReference* reference = document.project().findScene(m_sceneId);
    if (!reference) throw InvalidArgument("no scene '" + m_sceneId + "' to locate");
    m_oldPath = reference->path;
    const auto missing = document.missingScenes().find(m_sceneId);
    if (missing != document.missingScenes().end()) m_oldReason = missing->second;
}

void RelinkSceneCommand::redo()
{
    m_held = m_document.relinkScene(m_sceneId, m_newPath, std::move(m_held), {});
}

void RelinkSceneCommand::undo()
{
    m_held = m_document.relinkScene(m_sceneId, m_oldPath, std::move(m_held), m_oldReason);
}

QUndoCommand* makeSetHoseDefinition(Document& document, const std::string& hoseId,
                                    formats::HoseDefinition definition, MergeId mergeId,
                                    const QString& text)
{
    return new ChangeValue<formats::HoseDefinition>(
        document, text, [hoseId](Document& d) { return d.mutableHoseDefinition(hoseId); },
        [hoseId](Document& d) { d.hoseDefinitionChanged(hoseId); }, std::move(definition), mergeId,
        hoseId);
}

QUndoCommand* makeSetRoute(Document& document, const std::string& hoseId, std::vector<Vec3> route,
                           const QString& text, MergeId mergeId)
{
    return makeChangeHoseField(document, hoseId, &formats::HoseDefinition::route, std::move(route),
                               mergeId, text);
}

QUndoCommand* makeSetHoseLength(Document& document, const std::string& hoseId, double length)
{
    const formats::HoseDefinition* definition = document.hoseDefinition(hoseId);
    if (!definition) throw InvalidArgument("no hose '" + hoseId + "' to change");
    formats::HoseDefinition changed =
        formats::withLength(document.project(), *definition, document.scenes(), length);
    return makeSetHoseDefinition(document, hoseId, std::move(changed), MergeId::HoseLength,
                                 tr("Change length of %1").arg(hoseLabel(*definition)));
}

QUndoCommand* makeFitHoseLength(Document& document, const std::string& hoseId, double length)
{
    const formats::HoseDefinition* definition = document.hoseDefinition(hoseId);
    if (!definition) throw InvalidArgument("no hose '" + hoseId + "' to fit");
    formats::HoseDefinition changed =
        formats::withLength(document.project(), *definition, document.scenes(), length);
    return makeSetHoseDefinition(document, hoseId, std::move(changed), MergeId::None,
                                 tr("Fit length of %1").arg(hoseLabel(*definition)));
}

QUndoCommand* makeAttach(Document& document, const std::string& hoseId, int first, int last,
                         const std::string& sceneId, int node)
{
    const formats::HoseDefinition* definition = document.hoseDefinition(hoseId);
    const Hose* hose = document.hose(hoseId);
    const formats::ImportedScene* scene = document.scene(sceneId);
    if (!definition || !hose) throw InvalidArgument("no hose '" + hoseId + "' to fix");
    if (!scene || node < 0 || node >= static_cast<int>(scene->nodes.size()))
        throw InvalidArgument("no scene node to fix the hose to");
    if (first < 0 || last < first || last >= hose->pointCount())
        throw InvalidArgument("points [" + std::to_string(first) + ", " + std::to_string(last) +
                              "] are outside the hose's " + std::to_string(hose->pointCount()) +
                              " axis points");
    for (const formats::HoseAttachment& existing : definition->attachments)
        if (first <= existing.lastPoint && existing.firstPoint <= last)
            throw InvalidArgument("points [" + std::to_string(first) + ", " + std::to_string(last) +
                                  "] overlap the segment fixed to " + existing.node);
    formats::HoseAttachment attachment;
    attachment.scene = sceneId;
    attachment.node = scene->nodes[static_cast<size_t>(node)].path;
    // The hose is rebuilt from its route at the file pose, so the offset is taken there: the
    // fixed points keep their route positions relative to the node as it is in the file.
    attachment.offset = Frame::identity();
    attachment.firstPoint = first;
    attachment.lastPoint = last;
    std::vector<formats::HoseAttachment> attachments = definition->attachments;
    attachments.push_back(attachment);
    const QString points =
        first == last ? tr("point %1").arg(first) : tr("points %1–%2").arg(first).arg(last);
    return makeChangeHoseField(
        document, hoseId, &formats::HoseDefinition::attachments, std::move(attachments),
        MergeId::None,
        tr("Fix %1 of %2 to %3")
            .arg(points, hoseLabel(*definition), nodeLabel(document, {sceneId, node})));
}

QUndoCommand* makeAddClip(Document& document, const std::string& hoseId, int point,
                          const std::string& sceneId, int node, Hold hold)
{
    const formats::HoseDefinition* definition = document.hoseDefinition(hoseId);
    const Hose* hose = document.hose(hoseId);
    const formats::ImportedScene* scene = document.scene(sceneId);
    if (!definition || !hose) throw InvalidArgument("no hose '" + hoseId + "' to clip");
    if (!scene || node < 0 || node >= static_cast<int>(scene->nodes.size()))
        throw InvalidArgument("no scene node to put the clip on");
    if (point < 1 || point > hose->pointCount() - 2)
        throw InvalidArgument("a clip goes on an inner point (1 … " +
                              std::to_string(hose->pointCount() - 2) + "), not point " +
                              std::to_string(point));
    const auto fixed = [&](int i) {
        return std::any_of(definition->attachments.begin(), definition->attachments.end(),
                           [&](const formats::HoseAttachment& a) {
                               return i >= a.firstPoint && i <= a.lastPoint;
                           });
    };
    if (fixed(point) || (fixed(point - 1) && fixed(point + 1)))
        throw InvalidArgument("point " + std::to_string(point) +
                              " is fixed by an attachment: a clip needs a free segment");
    // Where the hose is built (formats::buildHose), every segment has the same rest length.
    double place = 0.0;
    for (int s = 0; s < point; ++s)
        place += hose->restLength(s);
    for (const formats::HoseClip& other : definition->clips)
        if (std::abs(other.place - place) < 2.0 * hose->restLength(point))
            throw InvalidArgument("point " + std::to_string(point) +
                                  " is within two segments of "
                                  "the clip on " +
                                  other.node);
    formats::HoseClip clip;
    clip.scene = sceneId;
    clip.node = scene->nodes[static_cast<size_t>(node)].path;
    clip.place = place;
    clip.hold = hold;
    std::vector<formats::HoseClip> clips = definition->clips;
    clips.push_back(clip);
    return makeChangeHoseField(
        document, hoseId, &formats::HoseDefinition::clips, std::move(clips), MergeId::None,
        tr("Clip point %1 of %2 to %3")
            .arg(point)
            .arg(hoseLabel(*definition), nodeLabel(document, {sceneId, node})));
}

QUndoCommand* makeDetach(Document& document, const std::string& hoseId, int index)
{
    const formats::HoseDefinition* definition = document.hoseDefinition(hoseId);
    if (!definition || index < 0 || index >= static_cast<int>(definition->attachments.size()))
        throw InvalidArgument("no attachment " + std::to_string(index) + " on hose '" + hoseId +
                              "'");
    std::vector<formats::HoseAttachment> attachments = definition->attachments;
    const formats::HoseAttachment& detached = attachments[static_cast<size_t>(index)];
    const std::string nodeName = detached.node.substr(detached.node.rfind('/') + 1);
    const QString text =
        tr("Detach %1 from %2").arg(hoseLabel(*definition), QString::fromStdString(nodeName));
    attachments.erase(attachments.begin() + index);
    return makeChangeHoseField(document, hoseId, &formats::HoseDefinition::attachments,
                               std::move(attachments), MergeId::None, text);
}

QUndoCommand* makeSetNodeTransform(Document& document, const NodeKey& node,
                                   std::optional<formats::Mat4> localTransform, const QString& text)
{
    // The first application is the author's move as it happens (a drag step: gravity hoses
    // follow it); every later one is an undo or a redo.
    auto applied = std::make_shared<bool>(false);
    return new ChangeValue<std::optional<formats::Mat4>>(
        document, text.isEmpty() ? tr("Move %1").arg(nodeLabel(document, node)) : text,
        [node](Document& d) { return d.mutablePoseOverride(node); },
        [node, applied](Document& d) {
            d.poseChanged(node, !*applied);
            *applied = true;
        },
        std::move(localTransform), MergeId::NodeTransform,
        node.first + "#" + std::to_string(node.second));
}

QUndoCommand* makeSetCollider(Document& document, const NodeKey& node, bool collider)
{
    const formats::ImportedScene* imported = document.scene(node.first);
    Q_ASSERT(imported && node.second >= 0 &&
             node.second < static_cast<int>(imported->nodes.size()));
    const formats::ColliderNode entry{node.first,
                                      imported->nodes[static_cast<size_t>(node.second)].path};
    std::vector<formats::ColliderNode> colliders = document.project().colliders;
    const auto found = std::find(colliders.begin(), colliders.end(), entry);
    if (collider && found == colliders.end())
        colliders.push_back(entry);
    else if (!collider && found != colliders.end())
        colliders.erase(found);
    return new ChangeValue<std::vector<formats::ColliderNode>>(
        document,
        (collider ? tr("Make %1 a collider") : tr("%1 no longer a collider"))
            .arg(nodeLabel(document, node)),
        [](Document& d) { return &d.mutableProject().colliders; },
        [node](Document& d) { d.collidersChanged(node); }, std::move(colliders));
}

QUndoCommand* makeSetPresets(Document& document, std::vector<formats::MaterialPreset> presets,
                             const QString& text)
{
    return new ChangeValue<std::vector<formats::MaterialPreset>>(
        document, text, [](Document& d) { return &d.mutableProject().materialPresets; },
        [](Document& d) { d.presetsChanged(); }, std::move(presets), MergeId::None);
}

QUndoCommand* makeSetExportSettings(Document& document, formats::ExportSettings settings)
{
    return new ChangeValue<formats::ExportSettings>(
        document, tr("Change export settings"),
        [](Document& d) { return &d.mutableProject().exportSettings; },
        [](Document& d) { d.projectSettingsChanged(); }, std::move(settings),
        MergeId::ExportSettings, "export");
}

QUndoCommand* makeSetCheckSettings(Document& document, formats::CheckSettings checks)
{
    return new ChangeValue<formats::CheckSettings>(
        document, tr("Change clearance threshold"),
        [](Document& d) { return &d.mutableProject().checks; },
        [](Document& d) { d.projectSettingsChanged(); }, std::move(checks), MergeId::CheckSettings,
        "checks");
}

namespace {

QUndoCommand* changeSockets(Document& document, std::vector<formats::Socket> sockets,
                            const QString& text)
{
    return new ChangeValue<std::vector<formats::Socket>>(
        document, text, [](Document& d) { return &d.mutableProject().sockets; },
        [](Document& d) { d.socketsChanged(); }, std::move(sockets));
}

} // namespace

QUndoCommand* makeAddSocket(Document& document, formats::Socket socket)
{
    const std::string problem = Document::validateSocket(socket);
    if (!problem.empty()) throw InvalidArgument(problem);
    if (socket.id.empty() || document.project().findSocket(socket.id))
        throw InvalidArgument("socket id '" + socket.id + "' is empty or used");
    const QString text =
        tr("Add socket %1 on %2")
            .arg(QString::fromStdString(socket.id),
                 QString::fromStdString(socket.node.substr(socket.node.rfind('/') + 1)));
    std::vector<formats::Socket> sockets = document.project().sockets;
    sockets.push_back(std::move(socket));
    return changeSockets(document, std::move(sockets), text);
}

QUndoCommand* makeRemoveSocket(Document& document, const std::string& socketId)
{
    std::vector<formats::Socket> sockets = document.project().sockets;
    const auto found = std::find_if(sockets.begin(), sockets.end(),
                                    [&](const formats::Socket& s) { return s.id == socketId; });
    if (found == sockets.end()) throw InvalidArgument("no socket '" + socketId + "'");
    sockets.erase(found);
    return changeSockets(document, std::move(sockets),
                         tr("Delete socket %1").arg(QString::fromStdString(socketId)));
}

QUndoCommand* makeSetSocket(Document& document, formats::Socket socket)
{
    const std::string problem = Document::validateSocket(socket);
    if (!problem.empty()) throw InvalidArgument(problem);
    std::vector<formats::Socket> sockets = document.project().sockets;
    const auto found = std::find_if(sockets.begin(), sockets.end(),
                                    [&](const formats::Socket& s) { return s.id == socket.id; });
    if (found == sockets.end()) throw InvalidArgument("no socket '" + socket.id + "'");
    *found = std::move(socket);
    return changeSockets(document, std::move(sockets),
                         tr("Change socket %1").arg(QString::fromStdString(found->id)));
}

} // namespace chaintube::editor
