#include "import_dialog.h"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QLabel>
#include <QPushButton>
#include <QRadioButton>
#include <QVBoxLayout>
#include <limits>
#include <utility>

namespace chaintube::editor {

namespace {

/// The units offered: name, metres per unit.
const std::pair<const char*, double> kUnits[] = {
    {QT_TRANSLATE_NOOP("chaintube::editor::ImportDialog", "metre"), 1.0},
    {QT_TRANSLATE_NOOP("chaintube::editor::ImportDialog", "centimetre"), 0.01},
    {QT_TRANSLATE_NOOP("chaintube::editor::ImportDialog", "millimetre"), 0.001},
    {QT_TRANSLATE_NOOP("chaintube::editor::ImportDialog", "inch"), 0.0254},
    {QT_TRANSLATE_NOOP("chaintube::editor::ImportDialog", "foot"), 0.3048},
};

QString upAxisName(formats::UpAxis axis)
{
    return formats::toString(axis);
}

} // namespace

std::pair<Vec3, Vec3> sceneBounds(const formats::ImportedScene& scene)
{
    Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 high = -low;
    for (size_t n = 0; n < scene.nodes.size(); ++n) {
        if (scene.nodes[n].meshes.empty()) continue;
        const formats::Mat4 world = scene.worldTransform(static_cast<int>(n));
        for (int meshIndex : scene.nodes[n].meshes) {
            const formats::SceneMesh& mesh = scene.meshes[static_cast<size_t>(meshIndex)];
            for (size_t v = 0; v < mesh.vertexCount(); ++v) {
                const Vec3 local(mesh.positions[3 * v], mesh.positions[3 * v + 1],
                                 mesh.positions[3 * v + 2]);
                const Vec3 p = (world * local.homogeneous()).head<3>();
                low = low.cwiseMin(p);
                high = high.cwiseMax(p);
            }
        }
    }
    return {low, high};
}

ImportDialog::ImportDialog(const formats::ImportedScene& scene, bool haveContent, QWidget* parent)
    : QDialog(parent), m_detected(scene.sourceUnits)
{
    setObjectName("importDialog");
    setWindowTitle(tr("Import %1").arg(QString::fromStdString(scene.file.filename().string())));
    const auto [low, high] = sceneBounds(scene);
    m_detectedSize =
        (low.array() <= high.array()).all() ? Eigen::Vector3d(high - low) : Eigen::Vector3d::Zero();
    auto* layout = new QVBoxLayout(this);
    auto* found = new QLabel(
        tr("%1 file. It was read in %2s (%3) with %4 up (%5).")
            .arg(QString::fromStdString(scene.format), QString::fromStdString(m_detected.unitName),
                 QString::fromUtf8(formats::toString(m_detected.unitSource)),
                 upAxisName(m_detected.upAxis),
                 QString::fromUtf8(formats::toString(m_detected.upAxisSource))));
    found->setObjectName("importAssumed");
    found->setWordWrap(true);
    layout->addWidget(found);

    auto* form = new QFormLayout;
    m_unit = new QComboBox;
    m_unit->setObjectName("importUnit");
    m_unit->addItem(tr("as read: %1").arg(QString::fromStdString(m_detected.unitName)));
    for (const auto& [name, metres] : kUnits)
        m_unit->addItem(tr(name), metres);
    m_unit->setToolTip(tr("The length one unit of the file stands for"));
    form->addRow(tr("Units"), m_unit);
    m_upAxis = new QComboBox;
    m_upAxis->setObjectName("importUpAxis");
    m_upAxis->addItem(tr("as read: %1").arg(upAxisName(m_detected.upAxis)));
    m_upAxis->addItem(tr("+Y"), int(formats::UpAxis::PositiveY));
    m_upAxis->addItem(tr("+Z"), int(formats::UpAxis::PositiveZ));
    m_upAxis->setToolTip(tr("The file's axis that points up (the project is +Y up)"));
    form->addRow(tr("Up axis"), m_upAxis);
    m_size = new QLabel;
    m_size->setObjectName("importSize");
    form->addRow(tr("Size"), m_size);
    layout->addLayout(form);

    auto* where = new QGroupBox(tr("Place the scene"));
    auto* whereLayout = new QVBoxLayout(where);
    m_atOrigin = new QRadioButton(tr("At the origin (centred, standing on the floor Y = 0)"));
    m_atOrigin->setObjectName("placeAtOrigin");
    m_beside = new QRadioButton(tr("Beside what is there (along +X, on the same floor)"));
    m_beside->setObjectName("placeBeside");
    m_beside->setEnabled(haveContent);
    m_asInFile = new QRadioButton(tr("Where the file puts it"));
    m_asInFile->setObjectName("placeAsInFile");
    whereLayout->addWidget(m_atOrigin);
    whereLayout->addWidget(m_beside);
    whereLayout->addWidget(m_asInFile);
    (haveContent ? m_beside : m_atOrigin)->setChecked(true);
    layout->addWidget(where);

    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    buttons->setObjectName("importButtons");
    buttons->button(QDialogButtonBox::Ok)->setText(tr("Import"));
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    layout->addWidget(buttons);
    connect(m_unit, &QComboBox::currentIndexChanged, this, &ImportDialog::updateSize);
    connect(m_upAxis, &QComboBox::currentIndexChanged, this, &ImportDialog::updateSize);
    updateSize();
}

std::optional<double> ImportDialog::metresPerUnit() const
{
    if (m_unit->currentIndex() <= 0) return std::nullopt;
    return m_unit->currentData().toDouble();
}

std::optional<formats::UpAxis> ImportDialog::upAxis() const
{
    if (m_upAxis->currentIndex() <= 0) return std::nullopt;
    return static_cast<formats::UpAxis>(m_upAxis->currentData().toInt());
}

ImportDialog::Placement ImportDialog::placement() const
{
    return m_atOrigin->isChecked() ? Placement::AtOrigin
           : m_beside->isChecked() ? Placement::BesideExisting
                                   : Placement::AsInFile;
}

void ImportDialog::updateSize()
{
    // The size the scene will have: the detected size scaled to the chosen unit, its height
    // along the chosen up axis (a +Y / +Z swap exchanges height and depth).
    Eigen::Vector3d size = m_detectedSize;
    if (const auto metres = metresPerUnit()) size *= *metres / m_detected.metresPerUnit;
    if (const auto axis = upAxis(); axis && *axis != m_detected.upAxis)
        std::swap(size.y(), size.z());
    m_size->setText(tr("%1 × %2 × %3 m (width × height × depth)")
                        .arg(size.x(), 0, 'g', 4)
                        .arg(size.y(), 0, 'g', 4)
                        .arg(size.z(), 0, 'g', 4));
}

} // namespace chaintube::editor
