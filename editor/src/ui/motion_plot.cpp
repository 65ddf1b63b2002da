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

MotionPlot::Layout MotionPlot::layout(const QFontMetrics& metrics) const
{
    Layout l;
    const int line = metrics.height();
    const double limits[2] = {m_series.minBendRadius, m_series.clearanceThreshold};
    const double caps[2] = {std::max(4.0 * m_series.minBendRadius, 0.0), 0.0};
    std::vector<double> MotionPlotSeries::Line::*values[2] = {&MotionPlotSeries::Line::bendRadius,
                                                              &MotionPlotSeries::Line::clearance};
    QString tops[2];
    int widest = metrics.horizontalAdvance(tr("0"));
    for (int p = 0; p < 2; ++p) {
        l.ceiling[p] = axisTop(m_series.out, m_series.back, values[p], limits[p], caps[p]);
        tops[p] = tr("%1 mm").arg(l.ceiling[p] * 1000.0, 0, 'f', 0);
        widest = std::max(widest, metrics.horizontalAdvance(tops[p]));
    }
    // The value labels sit left of the panels, as wide as the widest of them.
    l.left = widest + 10;
    l.right = width() - 8;
    l.top = line + 6;
    // The axis text below the panels: one line, or more when it is wider than the plot.
    const int axisWidth = std::max(1, l.right - l.left);
    const QRect axisNeeds = metrics.boundingRect(QRect(0, 0, axisWidth, 10 * line),
                                                 Qt::AlignHCenter | Qt::TextWordWrap, m_axisText);
    const int axisLines =
        m_axisText.isEmpty() ? 0 : std::clamp((axisNeeds.height() + line - 1) / line, 1, 3);
    l.bottom = height() - axisLines * line - 6;
    l.panelHeight = (l.bottom - l.top - l.gap) / 2;
    for (int p = 0; p < 2; ++p) {
        const int areaTop = l.top + p * (l.panelHeight + l.gap);
        const int areaBottom = areaTop + l.panelHeight - 1;
        l.labels.push_back(
            {tops[p], QRect(4, areaTop - 2, l.left - 8, line), int(Qt::AlignRight | Qt::AlignTop)});
        l.labels.push_back({tr("0"), QRect(4, areaBottom - line + 2, l.left - 8, line),
                            int(Qt::AlignRight | Qt::AlignBottom)});
    }
    if (axisLines > 0)
        l.labels.push_back({m_axisText, QRect(l.left, l.bottom + 2, axisWidth, axisLines * line),
                            int(Qt::AlignHCenter | Qt::AlignTop | Qt::TextWordWrap)});
    return l;
}

std::vector<MotionPlot::Label> MotionPlot::labels() const
{
    return layout(fontMetrics()).labels;
}

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
    const Layout l = layout(metrics);
    const int left = l.left;
    const int right = l.right;
    const int top = l.top;
    const int gap = l.gap;
    const int panelHeight = l.panelHeight;
    if (right - left < 20 || panelHeight < 20) return;
    for (const Label& label : l.labels)
        painter.drawText(label.rect, label.flags, label.text);

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
        const double ceiling = l.ceiling[p];
        const auto x = [&](double t) { return area.left() + t * area.width(); };
        const auto y = [&](double v) {
            return area.bottom() - std::clamp(v / ceiling, 0.0, 1.0) * area.height();
        };
        painter.setPen(text);
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
}

} // namespace chaintube::editor
