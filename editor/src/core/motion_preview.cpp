// The Document's motion preview: the project's moving parts posed at the Motions dock's slider
// values without an edit (document.h, "motion preview").
#include "chaintube/editor/document.h"

#include <algorithm>
#include <cmath>

namespace chaintube::editor {

void Document::dropMotionPreview()
{
    m_motionValues.clear();
    m_partMotions.reset();
    m_motionNodes.clear();
    m_motionLocal.clear();
    m_motionMovedHoses.clear();
}

bool Document::setMotionPreview(const std::vector<double>& requested, std::string* why)
{
    const std::vector<formats::PartMotion>& motions = m_project.motions;
    if (requested.size() != motions.size()) {
        if (why)
            *why = "expected " + std::to_string(motions.size()) + " motion value(s), got " +
                   std::to_string(requested.size());
        return false;
    }
    std::vector<double> values(requested.size());
    for (size_t i = 0; i < motions.size(); ++i) {
        if (!std::isfinite(requested[i])) {
            if (why) *why = "motion '" + motions[i].id + "': expected a finite value";
            return false;
        }
        values[i] = std::clamp(requested[i], motions[i].minimum, motions[i].maximum);
    }
    if (!m_partMotions) {
        // The motions need the scenes' node trees only: a copy without meshes.
        formats::ImportedScenes nodes;
        for (const auto& [id, imported] : m_scenes) {
            formats::ImportedScene skeleton;
            skeleton.file = imported.file;
            skeleton.format = imported.format;
            skeleton.nodes = imported.nodes;
            nodes.emplace(id, std::move(skeleton));
        }
        try {
            m_partMotions = std::make_unique<formats::PartMotions>(m_project, nodes);
        } catch (const std::exception& error) {
            if (why) *why = error.what();
            return false;
        }
        m_motionNodes = m_partMotions->posed();
    }
    if (std::all_of(values.begin(), values.end(), [](double v) { return v == 0.0; })) {
        clearMotionPreview();
        return true;
    }
    if (values == m_motionValues) return true;
    applyMotionPose(values);
    emit motionPreviewChanged();
    return true;
}

void Document::applyMotionPose(const std::vector<double>& values)
{
    const std::vector<formats::PartMotion>& motions = m_project.motions;
    const std::vector<double> from =
        m_motionValues.empty() ? std::vector<double>(values.size(), 0.0) : m_motionValues;
    // A jump (a key press, a click on the groove) is taken in steps no larger than
    // 1/kMotionPreviewSteps of a range, as a person dragging the handle moves the part.
    int steps = 1;
    for (size_t i = 0; i < motions.size(); ++i) {
        const double range = motions[i].maximum - motions[i].minimum;
        steps = std::max(steps,
                         static_cast<int>(std::ceil(
                             std::abs(values[i] - from[i]) / range * kMotionPreviewSteps - 1e-9)));
    }
    const auto carried = [this](const std::string& sceneId, const std::string& path) {
        const formats::ImportedScene* imported = scene(sceneId);
        return imported && m_partMotions->carried(sceneId, imported->findNode(path));
    };
    std::vector<const formats::HoseDefinition*> driven;
    for (const formats::HoseDefinition& definition : m_project.hoses)
        if (std::any_of(definition.attachments.begin(), definition.attachments.end(),
                        [&](const formats::HoseAttachment& attachment) {
                            return carried(attachment.scene, attachment.node);
                        }) ||
            std::any_of(
                definition.clips.begin(), definition.clips.end(),
                [&](const formats::HoseClip& clip) { return carried(clip.scene, clip.node); }))
            driven.push_back(&definition);
    std::vector<std::string> moved;
    const auto noteMoved = [&](const std::string& id) {
        if (std::find(moved.begin(), moved.end(), id) == moved.end()) moved.push_back(id);
        if (std::find(m_motionMovedHoses.begin(), m_motionMovedHoses.end(), id) ==
            m_motionMovedHoses.end())
            m_motionMovedHoses.push_back(id);
    };
    std::vector<double> step(values.size());
    for (int k = 1; k <= steps; ++k) {
        for (size_t i = 0; i < values.size(); ++i)
            step[i] = k == steps ? values[i] : from[i] + (values[i] - from[i]) * k / steps;
        m_partMotions->apply(step, m_motionNodes);
        m_motionLocal.clear();
        for (size_t i = 0; i < m_partMotions->size(); ++i) {
            const std::string& sceneId = m_partMotions->sceneOf(i);
            const int node = m_partMotions->nodeOf(i);
            m_motionLocal[{sceneId, node}] =
                m_motionNodes.at(sceneId).nodes[static_cast<size_t>(node)].localTransform;
        }
        m_motionValues = step;
        ++m_poseSerial;
        // As a part drag (poseChanged): carried colliders move, the hoses fixed to carried
        // parts follow, a moved collider pushes the hoses it now overlaps out.
        std::vector<const MeshCollider*> movedColliders;
        for (const LiveCollider& c : m_colliders)
            if (m_partMotions->carried(c.sceneId, c.node) &&
                c.collider->setFrame(nodeWorldFrame(c.sceneId, c.node)))
                movedColliders.push_back(c.collider.get());
        for (const formats::HoseDefinition* definition : driven) {
            auto live = m_live.find(definition->id);
            if (live == m_live.end() || !live->second.hose) continue;
            std::vector<int> ids;
            for (const Hose::Attachment& attachment : live->second.hose->attachments())
                ids.push_back(attachment.id);
            const std::vector<Frame> frames = posedAttachmentFrames(*definition);
            if (ids.size() != frames.size()) continue;
            live->second.lastUpdate = moveAttachmentsFully(*live->second.hose, ids, frames);
            noteMoved(definition->id);
        }
        if (movedColliders.empty()) continue;
        for (auto& [hoseId, live] : m_live) {
            if (!live.hose) continue;
            const bool near =
                std::any_of(live.hose->colliders().begin(), live.hose->colliders().end(),
                            [&](const auto& used) {
                                return std::find(movedColliders.begin(), movedColliders.end(),
                                                 used.get()) != movedColliders.end();
                            });
            if (!near) continue;
            const std::uint64_t revision = live.hose->revision();
            live.lastUpdate = live.hose->resolveCollisions();
            if (live.hose->revision() != revision) noteMoved(hoseId);
        }
    }
    for (const std::string& id : moved) {
        wakeGravity(id);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, id);
    }
    for (size_t i = 0; i < m_partMotions->size(); ++i) {
        ChangeEvent event;
        event.kind = ChangeEvent::Kind::PoseChanged;
        event.sceneId = m_partMotions->sceneOf(i);
        event.node = m_partMotions->nodeOf(i);
        emit changed(event);
    }
}

void Document::followMotionPreview(const std::string& hoseId)
{
    const formats::HoseDefinition* definition = hoseDefinition(hoseId);
    const auto live = m_live.find(hoseId);
    if (!definition || !m_partMotions || live == m_live.end() || !live->second.hose) return;
    const auto carriedNode = [&](const std::string& sceneId, const std::string& path) {
        const formats::ImportedScene* imported = scene(sceneId);
        return imported && m_partMotions->carried(sceneId, imported->findNode(path));
    };
    const bool carried =
        std::any_of(
            definition->attachments.begin(), definition->attachments.end(),
            [&](const formats::HoseAttachment& a) { return carriedNode(a.scene, a.node); }) ||
        std::any_of(definition->clips.begin(), definition->clips.end(),
                    [&](const formats::HoseClip& c) { return carriedNode(c.scene, c.node); });
    if (!carried) return;
    std::vector<int> ids;
    for (const Hose::Attachment& attachment : live->second.hose->attachments())
        ids.push_back(attachment.id);
    const std::vector<Frame> frames = posedAttachmentFrames(*definition);
    if (ids.size() == frames.size())
        live->second.lastUpdate = moveAttachmentsFully(*live->second.hose, ids, frames);
    if (std::find(m_motionMovedHoses.begin(), m_motionMovedHoses.end(), hoseId) ==
        m_motionMovedHoses.end())
        m_motionMovedHoses.push_back(hoseId);
}

void Document::clearMotionPreview()
{
    if (m_motionValues.empty()) {
        m_partMotions.reset();
        m_motionNodes.clear();
        return;
    }
    std::vector<NodeKey> nodes;
    for (size_t i = 0; i < m_partMotions->size(); ++i)
        nodes.push_back({m_partMotions->sceneOf(i), m_partMotions->nodeOf(i)});
    std::vector<const LiveCollider*> carriedColliders;
    for (const LiveCollider& c : m_colliders)
        if (m_partMotions->carried(c.sceneId, c.node)) carriedColliders.push_back(&c);
    const std::vector<std::string> moved = m_motionMovedHoses;
    dropMotionPreview();
    ++m_poseSerial;
    for (const LiveCollider* c : carriedColliders)
        c->collider->setFrame(nodeWorldFrame(c->sceneId, c->node));
    // Built again, each hose the preview moved is exactly what the project gives.
    for (const std::string& id : moved) {
        if (hoseIndex(id) < 0) continue;
        rebuildHose(id);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, id);
    }
    for (const NodeKey& node : nodes) {
        ChangeEvent event;
        event.kind = ChangeEvent::Kind::PoseChanged;
        event.sceneId = node.first;
        event.node = node.second;
        emit changed(event);
    }
    emit motionPreviewChanged();
}

} // namespace chaintube::editor
