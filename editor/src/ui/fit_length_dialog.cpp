#include "fit_length_dialog.h"

#include "chaintube/editor/commands.h"

#include <QApplication>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QLabel>
#include <QProgressDialog>
#include <QPushButton>
#include <QVBoxLayout>
#include <chaintube/formats/errors.h>
#include <cmath>

namespace chaintube::editor {

namespace {
QString metres(double value)
{
    return QString::number(value, 'f', 3) + " m";
}

/// What breaks beyond an end of the range, in words.
QString limitText(exporting::LengthLimit limit)
{
    switch (limit) {
    case exporting::LengthLimit::None:
        return QObject::tr("nothing");
    case exporting::LengthLimit::Taut:
        return QObject::tr("pulled taut between its ends");
    case exporting::LengthLimit::Stretch:
        return QObject::tr("a segment beyond its stretch band");
    case exporting::LengthLimit::Reach:
        return QObject::tr("an end out of reach");
    case exporting::LengthLimit::Bend:
        return QObject::tr("a bend beyond its limit");
    case exporting::LengthLimit::Clearance:
        return QObject::tr("too near an object");
    }
    return {};
}
} // namespace

FitLengthDialog::FitLengthDialog(const QString& hoseLabel, const exporting::LengthFit& fit,
                                 QWidget* parent)
    : QDialog(parent)
{
    setObjectName("fitLengthDialog");
    setWindowTitle(tr("Fit length of %1").arg(hoseLabel));
    auto* layout = new QVBoxLayout(this);
    auto* form = new QFormLayout;
    auto* range = new QLabel(tr("%1 … %2%3")
                                 .arg(metres(fit.shortest), metres(fit.longest),
                                      fit.longestAtSearchLimit ? tr(" (search limit)") : ""));
    range->setObjectName("fitLengthRange");
    form->addRow(tr("Valid over the motions:"), range);
    form->addRow(tr("Shorter:"), new QLabel(limitText(fit.shortestLimit)));
    form->addRow(
        tr("Longer:"),
        new QLabel(
            fit.longestAtSearchLimit
                ? tr("not limited up to twice the shortest")
                : tr("%1%2").arg(limitText(fit.longestLimit),
                                 fit.limitingObject.empty()
                                     ? QString()
                                     : " (" + QString::fromStdString(fit.limitingObject) + ")")));
    form->addRow(tr("Current length:"),
                 new QLabel(metres(fit.currentLength) +
                            (fit.currentValid ? tr(", in the range") : tr(", outside the range"))));
    m_length = new QDoubleSpinBox;
    m_length->setObjectName("fitLengthValue");
    m_length->setDecimals(3);
    m_length->setSuffix(" m");
    m_length->setSingleStep(0.001);
    // Whole millimetres inside the range: every value the box offers is valid.
    m_length->setRange(std::ceil(fit.shortest * 1000.0 - 1e-6) / 1000.0,
                       std::floor(fit.longest * 1000.0 + 1e-6) / 1000.0);
    m_length->setValue(defaultLength(fit));
    form->addRow(tr("New length:"), m_length);
    layout->addLayout(form);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    buttons->button(QDialogButtonBox::Ok)->setText(tr("Set Length"));
    buttons->button(QDialogButtonBox::Ok)->setDefault(true);
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    layout->addWidget(buttons);
    m_length->setFocus();
    m_length->selectAll();
}

double FitLengthDialog::chosenLength() const
{
    return m_length->value();
}

double FitLengthDialog::defaultLength(const exporting::LengthFit& fit)
{
    const double middle = 0.5 * (fit.shortest + fit.longest);
    const double withSlack = std::min(1.05 * fit.shortest, middle);
    return std::round(withSlack * 1000.0) / 1000.0;
}

bool fitHoseLengthInteractively(
    Document& document, const std::string& hoseId, QWidget* parent,
    const std::function<void(const QString&, const QString&)>& showError)
{
    const formats::HoseDefinition* definition = document.hoseDefinition(hoseId);
    if (!definition) {
        showError(QObject::tr("Fit length"), QObject::tr("Select a hose first."));
        return false;
    }
    const QString label =
        QString::fromStdString(definition->name.empty() ? definition->id : definition->name);
    const int index = document.hoseIndex(hoseId);
    if (!exporting::betweenFixedEnds(document.project(), *definition)) {
        showError(QObject::tr("Fit length"),
                  QObject::tr("%1 needs both ends fixed to parts to fit its length.").arg(label));
        return false;
    }
    QProgressDialog progress(QObject::tr("Fitting the length of %1 over the motions…").arg(label),
                             QObject::tr("Cancel"), 0, 1000, parent);
    progress.setObjectName("fitLengthProgress");
    progress.setWindowModality(Qt::WindowModal);
    progress.setMinimumDuration(300);
    exporting::LengthFitOptions options;
    options.progress = [&progress](double fraction) {
        progress.setValue(static_cast<int>(fraction * 1000.0));
        QApplication::processEvents();
        return !progress.wasCanceled();
    };
    exporting::LengthFit fit;
    try {
        fit = exporting::fitHoseLength(document.project(), document.scenes(), index, options);
    } catch (const formats::Cancelled&) {
        return false;
    } catch (const std::exception& error) {
        showError(QObject::tr("Fit length"), QString::fromUtf8(error.what()));
        return false;
    }
    progress.reset();
    if (!fit.valid) {
        showError(QObject::tr("Fit length"), QObject::tr("%1 has no valid length: %2")
                                                 .arg(label, QString::fromStdString(fit.reason)));
        return false;
    }
    FitLengthDialog dialog(label, fit, parent);
    if (dialog.exec() != QDialog::Accepted) return false;
    document.undoStack()->push(makeFitHoseLength(document, hoseId, dialog.chosenLength()));
    return true;
}

} // namespace chaintube::editor
