// ChainTube editor — the problems panel: hoses that cannot be built, overstretched segments,
// bends tighter than the material's minimum radius (or beyond its deflection angle), and ring
// self-intersection. The viewport tints the same regions red; clicking a problem selects the
// hose and the offending axis points.
#pragma once

#include "chaintube/editor/document.h"

#include <QListWidget>
#include <QTimer>
#include <memory>

class QCheckBox;
class QDoubleSpinBox;

namespace chaintube::editor {

/// One problem, as listed.
struct Problem
{
    Problem() = default;
    Problem(std::string hose, int first, int last, QString message, std::string scene = {},
            int sceneNode = -1)
        : hoseId(std::move(hose)), firstPoint(first), lastPoint(last), text(std::move(message)),
          sceneId(std::move(scene)), node(sceneNode)
    {
    }
    std::string hoseId;
    int firstPoint = -1; ///< offending axis points (−1: the whole hose)
    int lastPoint = -1;
    QString text;
    /// Clearance violations: the scene object (selected together with the hose on click).
    std::string sceneId;
    int node = -1;
    /// A finding of the motion sweep: the motion values where it occurs (a click previews
    /// the parts there, Document::setMotionPreview); empty for a finding at the current pose.
    std::vector<double> motionValues;
    /// A scene of the project whose file is missing (Document::missingScenes): its id. A click
    /// asks where it is (ProblemsPanel::locateSceneRequested).
    std::string missingScene;
};

/// All problems of a document, hose by hose (pure function; used by the panel and tests).
std::vector<Problem> findProblems(const Document& document);

class ProblemsPanel : public QListWidget
{
    Q_OBJECT
public:
    explicit ProblemsPanel(Document& document, QWidget* parent = nullptr);
    const std::vector<Problem>& problems() const { return m_problems; }
    ~ProblemsPanel() override;
    /// Recomputes now (normally done at most every 100 ms after a change).
    void refreshNow();
    /// Clearance check: hoses closer than the threshold to a scene object (a node
    /// with meshes other than the ones the hose is attached to) are listed and marked in the
    /// viewport (Document::clearanceMarkers). The controls sit above the list.
    QCheckBox* clearanceEnabled() const { return m_clearanceEnabled; }
    /// Millimetres; the project's threshold (project().checks, saved with the project):
    /// typing a value is an undoable edit of the project.
    QDoubleSpinBox* clearanceThreshold() const { return m_clearanceThreshold; }
    /// Findings of the motion sweep (the Motions dock's), listed after the others until
    /// replaced.
    void setSweepProblems(std::vector<Problem> problems);

signals:
    /// A missing scene's entry was clicked: the main window asks for its file (Locate…).
    void locateSceneRequested(const std::string& sceneId);

protected:
    void resizeEvent(QResizeEvent* event) override;

private:
    Document& m_document;
    std::vector<Problem> m_problems;
    std::vector<Problem> m_sweepProblems;
    QTimer m_throttle;
    QWidget* m_clearanceBar = nullptr;
    QCheckBox* m_clearanceEnabled = nullptr;
    QDoubleSpinBox* m_clearanceThreshold = nullptr;
    bool m_syncingThreshold = false;
    /// The threshold field shows project().checks (the default when unset).
    void showProjectThreshold();
    struct ClearanceCache;
    std::unique_ptr<ClearanceCache> m_clearanceCache; ///< scene colliders, rebuilt on change
};

} // namespace chaintube::editor
