#include "motion_plot.h"

#include <QPainter>
#include <QPainterPath>
#include <algorithm>
#include <cmath>
#include <limits>

namespace chaintube::editor {

MotionPlot::MotionPlot(QWidget* parent) : QWidget(parent)
{
    setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Preferred);
}

void MotionPlot::setSeries(MotionPlotSeries series, QString axisText)
{
    m_series = std::move(series);
    m_axisText = std::move(axisText);
    setObjectName(QString::fromStdString("motionPlot_" + m_series.hoseId));
    m_stale = false;
    update();
}

void MotionPlot::setMarker(std::optional<double> t)
{
    if (t == m_marker) return;
    m_marker = t;
    update();
}

void MotionPlot::setStale(bool stale)
{
    if (stale == m_stale) return;
    m_stale = stale;
    update();
}

namespace {

/// The top of a panel's value axis (metres): every finite value and the limit in view, but a
/// nearly straight hose's huge radius does not squash the rest (values above are drawn at the
/// top edge).
double axisTop(const MotionPlotSeries::Line& out, const MotionPlotSeries::Line& back,
               std::vector<double> MotionPlotSeries::Line::*values, double limit, double cap)
{
    double top = limit * 1.5;
    for (const MotionPlotSeries::Line* line : {&out, &back})
        for (double value : line->*values)
            if (std::isfinite(value)) top = std::max(top, value * 1.15); // off the edge
    if (cap > 0.0) top = std::min(top, cap);
    return top > 0.0 ? top : 1.0;
}

} // namespace

void MotionPlot::paintEvent(QPaintEvent*)
{
    QPainter painter(this);
    painter.setRenderHint(QPainter::Antialiasing);
    painter.fillRect(rect(), palette().base());
    const QFontMetrics metrics = painter.fontMetrics();
    const int line = metrics.height();
    const QColor text = m_stale ? palette().color(QPalette::Disabled, QPalette::Text)
                                : palette().color(QPalette::Text);
    painter.setPen(text);
    painter.drawText(QRect(4, 2, width() - 8, line), Qt::AlignLeft | Qt::AlignVCenter,
                     QString::fromStdString(m_series.hoseName) +
                         (m_stale ? tr(" (out of date)") : QString()));
    const int left = metrics.horizontalAdvance("888 mm") + 8;
    const int right = width() - 8;
    const int top = line + 6;
    const int bottom = height() - line - 6;
    const int gap = 6;
    const int panelHeight = (bottom - top - gap) / 2;
    if (right - left < 20 || panelHeight < 20) return;

    struct Panel
    {
        QString title;
        std::vector<double> MotionPlotSeries::Line::*values;
        double limit;
        double cap;
        QColor colour;
    };
    const Panel panels[] = {
        {tr("bend radius"), &MotionPlotSeries::Line::bendRadius, m_series.minBendRadius,
         std::max(4.0 * m_series.minBendRadius, 0.0), QColor(40, 110, 200)},
        {tr("clearance"), &MotionPlotSeries::Line::clearance, m_series.clearanceThreshold, 0.0,
         QColor(220, 130, 20)},
    };
    for (int p = 0; p < 2; ++p) {
        const Panel& panel = panels[p];
        const QRect area(left, top + p * (panelHeight + gap), right - left, panelHeight);
        painter.setPen(QPen(palette().color(QPalette::Mid), 1));
        painter.drawRect(area);
        const double ceiling =
            axisTop(m_series.out, m_series.back, panel.values, panel.limit, panel.cap);
        const auto x = [&](double t) { return area.left() + t * area.width(); };
        const auto y = [&](double v) {
            return area.bottom() - std::clamp(v / ceiling, 0.0, 1.0) * area.height();
        };
        painter.setPen(text);
        painter.drawText(QRect(0, area.top() - 2, left - 4, line), Qt::AlignRight | Qt::AlignTop,
                         tr("%1 mm").arg(ceiling * 1000.0, 0, 'f', 0));
        painter.drawText(QRect(0, area.bottom() - line + 2, left - 4, line),
                         Qt::AlignRight | Qt::AlignBottom, tr("0"));
        painter.drawText(area.adjusted(4, 1, -4, -1), Qt::AlignLeft | Qt::AlignTop, panel.title);
        // The limit: a red line with its value.
        if (panel.limit > 0.0) {
            painter.setPen(QPen(QColor(210, 40, 40), 1.5));
            painter.drawLine(QPointF(area.left(), y(panel.limit)),
                             QPointF(area.right(), y(panel.limit)));
            painter.drawText(QRectF(area.left(), y(panel.limit) - line, area.width() - 4, line),
                             Qt::AlignRight | Qt::AlignBottom,
                             tr("%1 mm").arg(panel.limit * 1000.0, 0, 'f', 1));
        }
        // The series; an infinite value (straight, nothing near) breaks the line.
        for (const auto& [series, style] :
             {std::pair{&m_series.out, Qt::SolidLine}, std::pair{&m_series.back, Qt::DashLine}}) {
            const std::vector<double>& values = series->*panel.values;
            QPainterPath path;
            bool drawing = false;
            for (size_t i = 0; i < series->t.size() && i < values.size(); ++i) {
                if (!std::isfinite(values[i])) {
                    drawing = false;
                    continue;
                }
                const QPointF at(x(series->t[i]), y(values[i]));
                if (drawing)
                    path.lineTo(at);
                else
                    path.moveTo(at);
                drawing = true;
            }
            painter.setPen(QPen(m_stale ? text : panel.colour, 1.5, style));
            painter.drawPath(path);
        }
        const auto finite = [](double value) { return std::isfinite(value); };
        const std::vector<double>& outValues = m_series.out.*panel.values;
        const std::vector<double>& backValues = m_series.back.*panel.values;
        const bool anyValue = std::any_of(outValues.begin(), outValues.end(), finite) ||
                              std::any_of(backValues.begin(), backValues.end(), finite);
        if (!anyValue) {
            painter.setPen(text);
            painter.drawText(area, Qt::AlignCenter,
                             p == 0 ? tr("straight at every step") : tr("no object near"));
        }
        if (m_marker) {
            painter.setPen(QPen(palette().color(QPalette::Highlight), 2));
            painter.drawLine(QPointF(x(*m_marker), area.top()),
                             QPointF(x(*m_marker), area.bottom()));
        }
    }
    painter.setPen(text);
    painter.drawText(QRect(left, bottom + 2, right - left, line), Qt::AlignCenter, m_axisText);
}

} // namespace chaintube::editor
