#include "motions_panel.h"

#include "chaintube/editor/motion_sweep.h"
#include "chaintube/formats/errors.h"
#include "motion_plot.h"

#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QSlider>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

namespace chaintube::editor {

MotionsPanel::MotionsPanel(Document& document, QWidget* parent)
    : QWidget(parent), m_document(document)
{
    setObjectName("motionsPanel");
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(4, 4, 4, 4);
    m_empty = new QLabel(tr("The project has no motions (hinges or sliders in its file)."), this);
    m_empty->setWordWrap(true);
    layout->addWidget(m_empty);
    m_rows = new QGridLayout;
    m_rows->setColumnStretch(1, 1);
    layout->addLayout(m_rows);
    auto* buttons = new QHBoxLayout;
    m_reset = new QPushButton(tr("Project pose"), this);
    m_reset->setObjectName("motionReset");
    m_reset->setToolTip(tr("Every moving part back to the project's pose (the preview ends)"));
    buttons->addWidget(m_reset);
    m_sweep = new QPushButton(tr("Sweep"), this);
    m_sweep->setObjectName("motionSweep");
    m_sweep->setToolTip(tr("Drives every motion through its range and back, as `chaintube check "
                           "--sweep` does, and plots each hose (it runs by itself after edits)"));
    buttons->addWidget(m_sweep);
    m_progress = new QProgressBar(this);
    m_progress->setObjectName("sweepProgress");
    m_progress->setRange(0, 1000);
    m_progress->setTextVisible(false);
    m_progress->setMaximumWidth(120);
    m_progress->hide();
    buttons->addWidget(m_progress);
    m_cancel = new QPushButton(tr("Cancel"), this);
    m_cancel->setObjectName("sweepCancel");
    m_cancel->hide();
    buttons->addWidget(m_cancel);
    m_sweepStatus = new QLabel(this);
    m_sweepStatus->setObjectName("sweepStatus");
    buttons->addWidget(m_sweepStatus, 1);
    layout->addLayout(buttons);
    // The plots, one per hose side by side (scrolling when they do not fit).
    auto* plots = new QWidget;
    m_plotRow = new QHBoxLayout(plots);
    m_plotRow->setContentsMargins(0, 0, 0, 0);
    auto* scroll = new QScrollArea(this);
    scroll->setWidget(plots);
    scroll->setWidgetResizable(true);
    scroll->setFrameShape(QFrame::NoFrame);
    scroll->setVerticalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    scroll->setMinimumHeight(MotionPlot().minimumSizeHint().height() +
                             scroll->horizontalScrollBar()->sizeHint().height());
    layout->addWidget(scroll, 1);
    connect(m_reset, &QPushButton::clicked, this, [this] { m_document.clearMotionPreview(); });
    connect(m_sweep, &QPushButton::clicked, this, &MotionsPanel::sweepNow);
    connect(m_cancel, &QPushButton::clicked, this, [this] {
        stopSweep();
        m_sweepStatus->setText(tr("Sweep cancelled"));
    });
    m_sweepDelay.setSingleShot(true);
    m_sweepDelay.setInterval(300);
    connect(&m_sweepDelay, &QTimer::timeout, this, &MotionsPanel::sweepNow);
    connect(&m_document, &Document::changed, this, [this](const ChangeEvent& event) {
        if (event.kind == ChangeEvent::Kind::ProjectReplaced) {
            rebuildRows();
            m_report.reset();
            m_findings.clear();
            for (MotionPlot* plot : m_plots)
                delete plot;
            m_plots.clear();
            sweepNow();
        } else if (event.kind == ChangeEvent::Kind::ScenesChanged) {
            rebuildRows();
        }
    });
    // Every edit (a command done, undone or redone) makes the sweep out of date.
    connect(m_document.undoStack(), &QUndoStack::indexChanged, this, [this] {
        for (MotionPlot* plot : m_plots)
            plot->setStale(true);
        m_sweepDelay.start();
    });
    connect(&m_document, &Document::motionPreviewChanged, this, [this] {
        syncFromDocument();
        updateMarkers();
    });
    rebuildRows();
}

MotionsPanel::~MotionsPanel()
{
    stopSweep();
}

void MotionsPanel::stopSweep()
{
    ++m_generation; // whatever it still delivers is dropped
    if (m_cancelFlag) *m_cancelFlag = true;
    if (m_thread.joinable()) m_thread.join();
    m_cancelFlag.reset();
    m_progress->hide();
    m_cancel->hide();
}

void MotionsPanel::setClearanceThreshold(double metres)
{
    if (metres == m_clearanceThreshold) return;
    m_clearanceThreshold = metres;
    for (MotionPlot* plot : m_plots)
        plot->setStale(true);
    m_sweepDelay.start();
}

void MotionsPanel::sweepNow()
{
    m_sweepDelay.stop();
    stopSweep();
    if (m_document.project().motions.empty()) {
        m_sweepStatus->clear();
        return;
    }
    const std::uint64_t generation = m_generation;
    auto cancel = std::make_shared<std::atomic<bool>>(false);
    m_cancelFlag = cancel;
    exporting::SweepOptions options;
    options.clearanceThreshold = m_clearanceThreshold;
    options.progress = [this, cancel, generation](double fraction) {
        QMetaObject::invokeMethod(
            this,
            [this, generation, fraction] {
                if (generation == m_generation) m_progress->setValue(int(fraction * 1000.0));
            },
            Qt::QueuedConnection);
        return !*cancel;
    };
    m_progress->setValue(0);
    m_progress->show();
    m_cancel->show();
    m_sweepStatus->setText(tr("Sweeping…"));
    m_finished = false;
    m_thread = std::thread(
        [this, generation, options, project = m_document.project(), scenes = m_document.scenes()] {
            std::shared_ptr<exporting::SweepReport> report;
            QString error;
            try {
                report = std::make_shared<exporting::SweepReport>(
                    exporting::sweepMotions(project, scenes, options));
            } catch (const formats::Cancelled&) {
                m_finished = true;
                return;
            } catch (const std::exception& failure) {
                error = QString::fromStdString(failure.what());
            }
            m_finished = true;
            QMetaObject::invokeMethod(
                this,
                [this, generation, report, error, project] {
                    if (generation == m_generation) finishSweep(report, error, project);
                },
                Qt::QueuedConnection);
        });
}

void MotionsPanel::finishSweep(std::shared_ptr<exporting::SweepReport> report, const QString& error,
                               const formats::Project& project)
{
    if (m_thread.joinable()) m_thread.join();
    m_cancelFlag.reset();
    m_progress->hide();
    m_cancel->hide();
    for (MotionPlot* plot : m_plots)
        delete plot;
    m_plots.clear();
    m_findings.clear();
    m_sweepError = error;
    if (!report) {
        m_report.reset();
        m_sweepStatus->setText(tr("Sweep failed: %1").arg(error));
        emit sweepFinished();
        return;
    }
    m_report = std::move(*report);
    m_findings = sweepFindings(*m_report, project);
    const exporting::SweepReport& swept = *m_report;
    int violating = 0;
    for (const exporting::HoseSweep& hose : swept.hoses)
        violating += hose.violates() ? 1 : 0;
    m_sweepStatus->setText(tr("%1 steps, %2 of %3 hoses break a limit")
                               .arg(swept.steps.size())
                               .arg(violating)
                               .arg(swept.hoses.size()));
    for (size_t h = 0; h < swept.hoses.size(); ++h) {
        auto* plot = new MotionPlot;
        plot->setSeries(plotSeries(swept, project, h), QString());
        m_plotRow->addWidget(plot);
        m_plots.push_back(plot);
    }
    updateMarkers();
    emit sweepFinished();
}

void MotionsPanel::updateMarkers()
{
    const std::vector<formats::PartMotion>& motions = m_document.project().motions;
    if (m_activeMotion < 0 || m_activeMotion >= int(motions.size())) return;
    const formats::PartMotion& motion = motions[size_t(m_activeMotion)];
    const std::vector<double>& preview = m_document.motionPreview();
    const double value = preview.empty() ? 0.0 : preview[size_t(m_activeMotion)];
    // The horizontal axis in the units of the slider last moved: t 0 … 1 is its range.
    const QString axis =
        tr("%1 %2 … %3  (out —, back - -)")
            .arg(QString::fromStdString(motion.id),
                 QString::fromStdString(formatMotionValue(motion, motion.minimum)),
                 QString::fromStdString(formatMotionValue(motion, motion.maximum)));
    for (MotionPlot* plot : m_plots) {
        if (plot->series().hoseId.empty()) continue;
        MotionPlotSeries series = plot->series();
        const bool stale = plot->stale();
        plot->setSeries(std::move(series), axis);
        plot->setStale(stale);
        plot->setMarker(driveParameterOf(motion, value));
    }
}

QSlider* MotionsPanel::slider(int motion) const
{
    return motion >= 0 && motion < int(m_sliders.size()) ? m_sliders[size_t(motion)] : nullptr;
}

QLabel* MotionsPanel::valueLabel(int motion) const
{
    return motion >= 0 && motion < int(m_values.size()) ? m_values[size_t(motion)] : nullptr;
}

void MotionsPanel::rebuildRows()
{
    for (QWidget* widget : m_rowWidgets)
        delete widget;
    m_rowWidgets.clear();
    m_sliders.clear();
    m_values.clear();
    m_activeMotion = 0;
    const std::vector<formats::PartMotion>& motions = m_document.project().motions;
    for (size_t i = 0; i < motions.size(); ++i) {
        const formats::PartMotion& motion = motions[i];
        const bool hinge = motion.kind == formats::PartMotion::Kind::Hinge;
        auto* name = new QLabel(tr("%1 (%2)").arg(QString::fromStdString(motion.id),
                                                  hinge ? tr("hinge") : tr("slider")),
                                this);
        name->setToolTip(QString::fromStdString(motion.scene + ":" + motion.node));
        auto* slider = new QSlider(Qt::Horizontal, this);
        slider->setObjectName(QString::fromStdString("motionSlider_" + motion.id));
        const MotionTicks ticks = motionTicks(motion);
        slider->setRange(ticks.minimum, ticks.maximum);
        slider->setSingleStep(10); // 1° or 1 mm
        slider->setPageStep(50);   // 5° or 5 mm
        slider->setValue(0);
        slider->setToolTip(
            tr("%1 … %2; drag to move the part, its hoses follow (a preview, not "
               "an edit)")
                .arg(QString::fromStdString(formatMotionValue(motion, motion.minimum)),
                     QString::fromStdString(formatMotionValue(motion, motion.maximum))));
        auto* value = new QLabel(this);
        value->setObjectName(QString::fromStdString("motionValue_" + motion.id));
        value->setMinimumWidth(value->fontMetrics().horizontalAdvance("-888.8 mm"));
        value->setAlignment(Qt::AlignRight | Qt::AlignVCenter);
        m_rows->addWidget(name, int(i), 0);
        m_rows->addWidget(slider, int(i), 1);
        m_rows->addWidget(value, int(i), 2);
        m_rowWidgets.insert(m_rowWidgets.end(), {name, slider, value});
        m_sliders.push_back(slider);
        m_values.push_back(value);
        connect(slider, &QSlider::valueChanged, this, &MotionsPanel::onSliderChanged);
    }
    m_empty->setVisible(motions.empty());
    m_reset->setEnabled(!motions.empty());
    syncFromDocument();
}

void MotionsPanel::onSliderChanged()
{
    if (m_syncing) return;
    const std::vector<formats::PartMotion>& motions = m_document.project().motions;
    if (motions.size() != m_sliders.size()) return;
    const auto moved = std::find(m_sliders.begin(), m_sliders.end(), sender());
    if (moved != m_sliders.end()) m_activeMotion = int(moved - m_sliders.begin());
    std::vector<double> values;
    for (size_t i = 0; i < motions.size(); ++i)
        values.push_back(motionValueOfTick(motions[i], m_sliders[i]->value()));
    std::string why;
    if (!m_document.setMotionPreview(values, &why)) {
        setToolTip(QString::fromStdString(why));
        syncFromDocument();
        return;
    }
    syncFromDocument(); // the labels (the document emits nothing for an unchanged preview)
    updateMarkers();
}

void MotionsPanel::syncFromDocument()
{
    const std::vector<formats::PartMotion>& motions = m_document.project().motions;
    if (motions.size() != m_sliders.size()) return;
    const std::vector<double>& preview = m_document.motionPreview();
    m_syncing = true;
    for (size_t i = 0; i < motions.size(); ++i) {
        const double value = preview.empty() ? 0.0 : preview[i];
        // A slider keeps its tick while it shows the previewed value (a tick at a range end
        // is clamped to the end, so the tick is not recomputed from the value).
        if (motionValueOfTick(motions[i], m_sliders[i]->value()) != value)
            m_sliders[i]->setValue(motionTickOfValue(motions[i], value));
        m_values[i]->setText(QString::fromStdString(formatMotionValue(motions[i], value)));
    }
    m_syncing = false;
}

} // namespace chaintube::editor
