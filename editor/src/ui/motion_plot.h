// ChainTube editor — a small plot of one hose over a motion sweep: bend radius (top) and
// clearance (bottom) against the drive parameter, the way out solid and the way back dashed,
// the limits (minimum bend radius, clearance threshold) as red lines and a marker where the
// Motions dock's slider is. Painted with QPainter.
#pragma once

#include "chaintube/editor/motion_sweep.h"

#include <QRect>
#include <QWidget>
#include <optional>
#include <vector>

namespace chaintube::editor {

class MotionPlot : public QWidget
{
    Q_OBJECT
public:
    explicit MotionPlot(QWidget* parent = nullptr);

    /// What is drawn; `axisText` labels the horizontal axis ("lever −28.6° … 45.8°").
    void setSeries(MotionPlotSeries series, QString axisText);
    const MotionPlotSeries& series() const { return m_series; }
    /// The marker (drive parameter t), none when the slider's value is off the sweep's path.
    void setMarker(std::optional<double> t);
    std::optional<double> marker() const { return m_marker; }
    /// Out of date: the project changed since the sweep (drawn greyed).
    void setStale(bool stale);
    bool stale() const { return m_stale; }

    /// A text the plot draws outside its panels (the value axes' top and 0, the horizontal
    /// axis): where, in widget coordinates. The layout leaves room for each: its rectangle
    /// lies inside the widget and is as wide as the text (the axis text wraps onto up to three
    /// lines when it is wider than the plot).
    struct Label
    {
        QString text;
        QRect rect;
        int flags = 0; ///< Qt::Alignment | Qt::TextFlag
    };
    std::vector<Label> labels() const;

    QSize sizeHint() const override { return {300, 220}; }
    QSize minimumSizeHint() const override { return {240, 200}; }

protected:
    void paintEvent(QPaintEvent* event) override;

private:
    struct Layout
    {
        int left = 0, right = 0, top = 0, bottom = 0, panelHeight = 0, gap = 6;
        double ceiling[2] = {1.0, 1.0}; ///< metres at the top of each panel
        std::vector<Label> labels;
    };
    Layout layout(const QFontMetrics& metrics) const;
    MotionPlotSeries m_series;
    QString m_axisText;
    std::optional<double> m_marker;
    bool m_stale = false;
};

} // namespace chaintube::editor
