// ChainTube editor — undo commands. Every edit of a Document is one of these.
//
// Parameter edits go through one generic template, ChangeValue<Value>: it swaps a value in
// the document with the one it holds (so redo and undo are the same operation) and tells the
// document what changed. Consecutive changes of the same thing with the same MergeId within
// one merge run (Document::closeMerge() ends a run, e.g. on slider release) merge into one
// undo step, so a slider drag is a single step.
#pragma once

#include "chaintube/editor/document.h"

#include <QUndoCommand>
#include <functional>
#include <optional>
#include <string>
#include <utility>

namespace chaintube::editor {

/// Merge ids (QUndoCommand::id()), one per kind of continuous edit.
enum class MergeId : int {
    None = -1,
    HoseName = 1,
    HoseDiameter,
    HoseSegments,
    HoseMaterial,
    HoseProfile,
    HoseColour,
    HoseRoute,
    HoseLength,
    HoseAttachments,
    HoseDefinition,
    NodeTransform,
    Presets,
    ExportSettings,
    Colliders,
    CheckSettings,
    Sockets,
};

/// The generic value change. `access` finds the value in the document (nullptr if it no longer
/// exists, which makes redo/undo a no-op); `notify` tells the document what changed after a
/// swap. `mergeKey` names the thing changed (e.g. the hose id) so that only changes of the
/// same thing merge.
template <typename Value> class ChangeValue : public QUndoCommand
{
public:
    using Access = std::function<Value*(Document&)>;
    using Notify = std::function<void(Document&)>;

    ChangeValue(Document& document, const QString& text, Access access, Notify notify,
                Value newValue, MergeId mergeId = MergeId::None, std::string mergeKey = {})
        : QUndoCommand(text), m_document(document), m_access(std::move(access)),
          m_notify(std::move(notify)), m_value(std::move(newValue)), m_mergeId(mergeId),
          m_mergeKey(std::move(mergeKey)), m_generation(document.mergeGeneration())
    {
    }

    void redo() override { swap(); }
    void undo() override { swap(); }
    int id() const override { return static_cast<int>(m_mergeId); }
    bool mergeWith(const QUndoCommand* other) override
    {
        // redo() of `other` already put its value in the document; keeping our held value
        // (the one before the whole run) makes undo go back to the start of the run.
        const auto* next = dynamic_cast<const ChangeValue*>(other);
        return next && m_mergeId != MergeId::None && next->m_mergeKey == m_mergeKey &&
               next->m_generation == m_generation;
    }

private:
    void swap()
    {
        if (Value* current = m_access(m_document)) {
            std::swap(*current, m_value);
            m_notify(m_document);
        }
    }

    Document& m_document;
    Access m_access;
    Notify m_notify;
    Value m_value;
    MergeId m_mergeId;
    std::string m_mergeKey;
    std::uint64_t m_generation;
};

/// Adds a hose at the end of the project (redo) / removes it (undo).
class AddHoseCommand : public QUndoCommand
{
public:
    AddHoseCommand(Document& document, formats::HoseDefinition definition);
    void redo() override;
    void undo() override;

private:
    Document& m_document;
    formats::HoseDefinition m_definition;
    int m_index = 0;
};

/// Removes a hose (redo) / puts it back at its index (undo).
class RemoveHoseCommand : public QUndoCommand
{
public:
    RemoveHoseCommand(Document& document, std::string hoseId);
    void redo() override;
    void undo() override;

private:
    Document& m_document;
    std::string m_hoseId;
    formats::HoseDefinition m_definition;
    int m_index = -1;
};

/// Adds an imported scene and its reference (redo) / removes them (undo).
class AddSceneCommand : public QUndoCommand
{
public:
    AddSceneCommand(Document& document, formats::SceneReference reference,
                    formats::ImportedScene scene);
    void redo() override;
    void undo() override;

private:
    Document& m_document;
    formats::SceneReference m_reference;
    formats::ImportedScene m_scene;
};

/// Points a scene at another file (Locate… for a missing scene): redo sets the new path and
/// the scene read from it, undo the old path and the scene missing again (or the scene it had).
class RelinkSceneCommand : public QUndoCommand
{
public:
    RelinkSceneCommand(Document& document, std::string sceneId, std::string newPath,
                       formats::ImportedScene scene);
    void redo() override;
    void undo() override;

private:
    Document& m_document;
    std::string m_sceneId;
    std::string m_oldPath, m_newPath;
    std::string m_oldReason;                      ///< why it was missing ("" if it was not)
    std::optional<formats::ImportedScene> m_held; ///< the scene the document does not hold
};

// --- the concrete edits (each is a ChangeValue) -----------------------------------------------

/// Any hose field through a member pointer, e.g. &HoseDefinition::outerDiameter.
template <typename Value>
QUndoCommand* makeChangeHoseField(Document& document, const std::string& hoseId,
                                  Value formats::HoseDefinition::*field, Value newValue,
                                  MergeId mergeId, const QString& text)
{
    return new ChangeValue<Value>(
        document, text,
        [hoseId, field](Document& d) -> Value* {
            formats::HoseDefinition* definition = d.mutableHoseDefinition(hoseId);
            return definition ? &(definition->*field) : nullptr;
        },
        [hoseId](Document& d) { d.hoseDefinitionChanged(hoseId); }, std::move(newValue), mergeId,
        hoseId);
}

/// Replaces a hose's whole definition (the properties panel: one field changed, checked with
/// Document::validateHoseDefinition first). `mergeId` names the field so that a slider drag
/// merges into one step.
QUndoCommand* makeSetHoseDefinition(Document& document, const std::string& hoseId,
                                    formats::HoseDefinition definition, MergeId mergeId,
                                    const QString& text);

/// Replaces a hose's route (insert/delete/move a route point; commit of a grab-drag). Pass
/// MergeId::HoseRoute while a route point is dragged so that the drag is one step.
QUndoCommand* makeSetRoute(Document& document, const std::string& hoseId, std::vector<Vec3> route,
                           const QString& text, MergeId mergeId = MergeId::None);

/// Makes a hose `length` metres long where it lies (formats::withLength: the route becomes
/// the hose's shape with the length added as slack between its held ends, or pulled in).
/// Consecutive length edits of the same hose merge (a spin box held down). Throws
/// InvalidArgument (an unknown hose, a length ≤ 0, no room for the attachments).
QUndoCommand* makeSetHoseLength(Document& document, const std::string& hoseId, double length);

/// Sets a hose's length chosen from its fitted range ("Fit length…"): as makeSetHoseLength, but
/// never merged with another edit, so the fit is one undo step of its own.
QUndoCommand* makeFitHoseLength(Document& document, const std::string& hoseId, double length);

/// Fixes axis points [first, last] of a hose to a scene node at their current place.
/// Throws InvalidArgument if the range is outside the hose or overlaps an attachment.
QUndoCommand* makeAttach(Document& document, const std::string& hoseId, int first, int last,
                         const std::string& sceneId, int node);

/// Adds a clip (formats::HoseClip) on a scene node where the hose is at axis point `point`
/// (1 … points − 2): the hose passes through it along its axis there and slides through it when
/// its part moves. Throws InvalidArgument if the point is an end, both segments at it are
/// fixed by an attachment, or another clip is within a segment of it.
QUndoCommand* makeAddClip(Document& document, const std::string& hoseId, int point,
                          const std::string& sceneId, int node, Hold hold = Hold::Sliding);

/// Removes attachment `index` (in the definition's order).
QUndoCommand* makeDetach(Document& document, const std::string& hoseId, int index);

/// Sets (or with nullopt clears) a node's transform override; merges while dragging. `text`
/// names the step in the history ("" = "Move <node name>").
QUndoCommand* makeSetNodeTransform(Document& document, const NodeKey& node,
                                   std::optional<formats::Mat4> localTransform,
                                   const QString& text = QString());

/// Flags (or unflags) a scene node as a collider (project().colliders). A flag that
/// is already as asked gives a command that changes nothing. The node must exist.
QUndoCommand* makeSetCollider(Document& document, const NodeKey& node, bool collider);

/// Replaces the project's material presets (saving an own preset).
QUndoCommand* makeSetPresets(Document& document, std::vector<formats::MaterialPreset> presets,
                             const QString& text);

/// Replaces the export settings.
QUndoCommand* makeSetExportSettings(Document& document, formats::ExportSettings settings);
/// The project's check thresholds (project().checks: the clearance threshold the Problems
/// panel and `chaintube check` use); consecutive changes merge into one step.
QUndoCommand* makeSetCheckSettings(Document& document, formats::CheckSettings checks);

/// Adds a socket at the end of project().sockets (the "Add Socket" tool). Throws
/// InvalidArgument when Document::validateSocket refuses it or its id is taken.
QUndoCommand* makeAddSocket(Document& document, formats::Socket socket);
/// Removes the socket with this id. Throws InvalidArgument for an unknown id.
QUndoCommand* makeRemoveSocket(Document& document, const std::string& socketId);
/// Replaces a socket's values (the properties panel: radius, angle, tag), one step per edit.
/// Throws InvalidArgument for an unknown id, a changed id, or values validateSocket refuses.
QUndoCommand* makeSetSocket(Document& document, formats::Socket socket);

} // namespace chaintube::editor
