#include "motions_panel.h"

#include "chaintube/editor/motion_sweep.h"

#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QVBoxLayout>

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
    buttons->addStretch(1);
    layout->addLayout(buttons);
    layout->addStretch(1);
    connect(m_reset, &QPushButton::clicked, this, [this] { m_document.clearMotionPreview(); });
    connect(&m_document, &Document::changed, this, [this](const ChangeEvent& event) {
        if (event.kind == ChangeEvent::Kind::ProjectReplaced ||
            event.kind == ChangeEvent::Kind::ScenesChanged)
            rebuildRows();
    });
    connect(&m_document, &Document::motionPreviewChanged, this, &MotionsPanel::syncFromDocument);
    rebuildRows();
}

MotionsPanel::~MotionsPanel() = default;

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
