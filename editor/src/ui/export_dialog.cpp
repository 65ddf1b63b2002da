#include "export_dialog.h"

#include "chaintube/editor/export_integration.h"
#include "import_runner.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QVBoxLayout>

namespace chaintube::editor {

ExportDialog::ExportDialog(Document& document, QWidget* parent)
    : QDialog(parent), m_document(document)
{
    setObjectName("exportDialog");
    setWindowTitle(tr("Export hose rig"));
    auto* layout = new QVBoxLayout(this);
    auto* form = new QFormLayout;
    m_output = new QLineEdit;
    m_output->setObjectName("exportOutput");
    auto* browse = new QPushButton(tr("Browse…"));
    auto* outputRow = new QHBoxLayout;
    outputRow->addWidget(m_output, 1);
    outputRow->addWidget(browse);
    form->addRow(tr("File"), outputRow);
    m_format = new QComboBox;
    m_format->addItems({tr("GLB (binary)"), tr("glTF + .bin")});
    form->addRow(tr("Format"), m_format);
    m_includeScene = new QCheckBox(tr("Include the scene's meshes"));
    m_includeScene->setChecked(document.project().exportSettings.includeScene);
    form->addRow(QString(), m_includeScene);
    m_descriptor = new QCheckBox(tr("Write the hose-rig descriptor beside (.hoses.json)"));
    m_descriptor->setChecked(true);
    form->addRow(QString(), m_descriptor);
    layout->addLayout(form);
    m_summary = new QPlainTextEdit;
    m_summary->setObjectName("exportSummary");
    m_summary->setReadOnly(true);
    m_summary->setMinimumHeight(140);
    layout->addWidget(m_summary);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Close);
    m_exportButton = buttons->addButton(tr("Export"), QDialogButtonBox::AcceptRole);
    m_exportButton->setObjectName("exportButton");
    layout->addWidget(buttons);

    // Default output: the project's export settings, else <project>.glb beside the project.
    const auto& settings = document.project().exportSettings;
    std::filesystem::path output;
    if (!document.fileName().empty()) {
        output =
            document.fileName().parent_path() /
            (settings.path.empty() ? document.fileName().stem().string() + "." + settings.format
                                   : settings.path);
    }
    m_output->setText(QString::fromStdString(output.string()));
    m_format->setCurrentIndex(settings.format == "gltf" ? 1 : 0);
    connect(m_format, &QComboBox::currentIndexChanged, this, [this](int index) {
        QString path = m_output->text();
        const int dot = path.lastIndexOf('.');
        if (dot > 0) path = path.left(dot);
        m_output->setText(path + (index == 1 ? ".gltf" : ".glb"));
    });
    connect(browse, &QPushButton::clicked, this, [this] {
        const QString path = QFileDialog::getSaveFileName(this, tr("Export to"), m_output->text(),
                                                          tr("glTF (*.glb *.gltf)"));
        if (!path.isEmpty()) m_output->setText(path);
    });
    connect(m_exportButton, &QPushButton::clicked, this, [this] { runExport(); });
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    if (!exportAvailable()) {
        m_exportButton->setEnabled(false);
        m_summary->setPlainText(tr("This build has no export library (chaintube_export)."));
    }
}

void ExportDialog::setOutputPath(const QString& path)
{
    m_output->setText(path);
}

QString ExportDialog::summaryText() const
{
    return m_summary->toPlainText();
}

bool ExportDialog::runExport()
{
    ExportRequest request;
    request.output = m_output->text().toStdString();
    request.includeSceneMeshes = m_includeScene->isChecked();
    request.writeSidecarDescriptor = m_descriptor->isChecked();
    ExportSummary summary;
    QString error;
    const formats::Project project = m_document.project();
    const std::filesystem::path projectFile =
        m_document.fileName().empty() ? std::filesystem::current_path() / "untitled.ctproj"
                                      : m_document.fileName();
    const formats::NamedRoots roots = m_document.roots();
    const bool ok = runWithProgress(
        this, tr("Exporting…"),
        [&](const std::function<bool(double)>& progress) {
            request.progress = progress;
            summary = exportProjectForEditor(project, projectFile, roots, request);
        },
        &error);
    if (!ok) {
        m_summary->setPlainText(tr("Export failed: %1").arg(error));
        return false;
    }
    // Each file written on a line of its own with its size: the glTF, its buffer, the
    // descriptor beside it.
    const auto written = [this](const std::filesystem::path& file, const QString& what) {
        const QFileInfo info(QString::fromStdString(file.string()));
        const double bytes = double(info.size());
        const QString size = bytes >= 1e6   ? tr("%1 MB").arg(bytes / 1e6, 0, 'f', 1)
                             : bytes >= 1e3 ? tr("%1 KB").arg(bytes / 1e3, 0, 'f', 1)
                                            : tr("%1 bytes").arg(info.size());
        return tr("  %1  %2  (%3)").arg(info.fileName(), size, what);
    };
    QStringList lines;
    lines << tr("Wrote in %1 s to %2:")
                 .arg(summary.seconds, 0, 'f', 2)
                 .arg(QString::fromStdString(summary.gltfFile.parent_path().string()));
    lines << written(summary.gltfFile, tr("glTF"));
    if (!summary.binFile.empty()) lines << written(summary.binFile, tr("glTF buffer"));
    if (!summary.descriptorFile.empty())
        lines << written(summary.descriptorFile, tr("hose descriptor"));
    lines << tr("%1 hoses, %2 joints, %3 scene nodes")
                 .arg(summary.hoseCount)
                 .arg(summary.jointCount)
                 .arg(summary.sceneNodeCount);
    for (const std::string& warning : summary.warnings)
        lines << tr("Warning: %1").arg(QString::fromStdString(warning));
    m_summary->setPlainText(lines.join('\n'));
    return true;
}

} // namespace chaintube::editor
