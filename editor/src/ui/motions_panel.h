// ChainTube editor — the Motions dock: a slider per project motion (hinge or slider) that
// scrubs the part's pose live as a preview (Document::setMotionPreview: no undo step, the
// project unchanged; "Project pose" returns to it), and per hose a plot of bend radius and
// clearance over the motion sweep (exporting::sweepMotions, the sweep of `chaintube check
// --sweep`), run on a worker thread after every edit, with progress and Cancel.
#pragma once

#include "chaintube/editor/document.h"
#include "chaintube/editor/motion_sweep.h"

#include <QTimer>
#include <QWidget>
#include <atomic>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

class QHBoxLayout;
class QLabel;
class QProgressBar;
class QPushButton;
class QSlider;
class QGridLayout;

namespace chaintube::editor {

class MotionPlot;

class MotionsPanel : public QWidget
{
    Q_OBJECT
public:
    explicit MotionsPanel(Document& document, QWidget* parent = nullptr);
    ~MotionsPanel() override;

    /// The slider of project().motions[motion] (ticks: motionTicks), nullptr out of range.
    QSlider* slider(int motion) const;
    /// Its value as shown ("35.0°", "12.0 mm").
    QLabel* valueLabel(int motion) const;
    /// "Project pose": every motion back to 0 (Document::clearMotionPreview).
    QPushButton* resetButton() const { return m_reset; }

    // --- the sweep --------------------------------------------------------------------------
    /// Sweeps the document's project now on a worker thread (a running sweep is cancelled):
    /// a copy of the project and scenes, the clearance threshold set here, default steps. Done
    /// by itself after a new project and, 300 ms after the last one, after every edit.
    void sweepNow();
    /// The threshold of the sweep's clearance (metres; 0: collisions only); sweeps again.
    void setClearanceThreshold(double metres);
    bool sweepRunning() const { return m_thread.joinable() && !m_finished; }
    /// The last finished sweep (none before one, or after it failed: sweepError()).
    const std::optional<exporting::SweepReport>& report() const { return m_report; }
    const std::vector<SweepFinding>& findings() const { return m_findings; }
    const QString& sweepError() const { return m_sweepError; }
    /// One plot per hose of the last sweep, project order.
    const std::vector<MotionPlot*>& plots() const { return m_plots; }
    QPushButton* sweepButton() const { return m_sweep; }
    QPushButton* cancelButton() const { return m_cancel; }
    QProgressBar* progress() const { return m_progress; }

signals:
    /// A sweep ended: report(), findings() and the plots are its (or sweepError() says why
    /// not). Not emitted for a cancelled sweep.
    void sweepFinished();

private:
    /// Rows for the project's motions (after a new project or scene change).
    void rebuildRows();
    /// Sliders and labels to the document's preview (signals blocked).
    void syncFromDocument();
    void onSliderChanged();
    /// Cancels and joins the worker, if any.
    void stopSweep();
    void finishSweep(std::shared_ptr<exporting::SweepReport> report, const QString& error,
                     const formats::Project& project);
    /// Every plot's marker at the slider last moved.
    void updateMarkers();

    Document& m_document;
    QGridLayout* m_rows = nullptr;
    QLabel* m_empty = nullptr;
    QPushButton* m_reset = nullptr;
    std::vector<QSlider*> m_sliders;
    std::vector<QLabel*> m_values;
    std::vector<QWidget*> m_rowWidgets;
    bool m_syncing = false;
    int m_activeMotion = 0; ///< the slider last moved: its value is the plots' marker

    QPushButton* m_sweep = nullptr;
    QPushButton* m_cancel = nullptr;
    QProgressBar* m_progress = nullptr;
    QLabel* m_sweepStatus = nullptr;
    QHBoxLayout* m_plotRow = nullptr;
    std::vector<MotionPlot*> m_plots;
    QTimer m_sweepDelay; ///< after an edit
    double m_clearanceThreshold = 0.0;
    std::thread m_thread;
    std::shared_ptr<std::atomic<bool>> m_cancelFlag;
    std::atomic<bool> m_finished{true};
    std::uint64_t m_generation = 0; ///< results of an older sweep are dropped
    std::optional<exporting::SweepReport> m_report;
    std::vector<SweepFinding> m_findings;
    QString m_sweepError;
};

} // namespace chaintube::editor
