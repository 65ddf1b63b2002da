// ChainTube editor — the Motions dock: a slider per project motion (hinge or slider) that
// scrubs the part's pose live as a preview (Document::setMotionPreview: no undo step, the
// project unchanged; "Project pose" returns to it).
#pragma once

#include "chaintube/editor/document.h"

#include <QWidget>
#include <vector>

class QLabel;
class QPushButton;
class QSlider;
class QGridLayout;

namespace chaintube::editor {

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

private:
    /// Rows for the project's motions (after a new project or scene change).
    void rebuildRows();
    /// Sliders and labels to the document's preview (signals blocked).
    void syncFromDocument();
    void onSliderChanged();

    Document& m_document;
    QGridLayout* m_rows = nullptr;
    QLabel* m_empty = nullptr;
    QPushButton* m_reset = nullptr;
    std::vector<QSlider*> m_sliders;
    std::vector<QLabel*> m_values;
    std::vector<QWidget*> m_rowWidgets;
    bool m_syncing = false;
};

} // namespace chaintube::editor
