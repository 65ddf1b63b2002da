#include "properties_panel.h"

#include "chaintube/editor/commands.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/route.h"

#include <QAbstractScrollArea>
#include <QAbstractSpinBox>
#include <QApplication>
#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QCoreApplication>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QInputDialog>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QLocale>
#include <QPushButton>
#include <QScrollBar>
#include <QSlider>
#include <QSpinBox>
#include <QStandardItemModel>
#include <QVBoxLayout>
#include <QVector3D>
#include <cmath>
#include <iterator>
#include <numbers>
#include <utility>

namespace chaintube::editor {

namespace {

/// The shape box's last item: a polygon profile (shown, not offered).
constexpr int kPolygonShapeIndex = 4;

/// Gravity directions offered (world; the project is +Y up, so −Y is down).
const std::pair<const char*, Vec3> kGravityDirections[] = {
    {QT_TRANSLATE_NOOP("chaintube::editor::PropertiesPanel", "down (−Y)"), Vec3(0, -1, 0)},
    {QT_TRANSLATE_NOOP("chaintube::editor::PropertiesPanel", "up (+Y)"), Vec3(0, 1, 0)},
    {QT_TRANSLATE_NOOP("chaintube::editor::PropertiesPanel", "−X"), Vec3(-1, 0, 0)},
    {QT_TRANSLATE_NOOP("chaintube::editor::PropertiesPanel", "+X"), Vec3(1, 0, 0)},
    {QT_TRANSLATE_NOOP("chaintube::editor::PropertiesPanel", "−Z"), Vec3(0, 0, -1)},
    {QT_TRANSLATE_NOOP("chaintube::editor::PropertiesPanel", "+Z"), Vec3(0, 0, 1)},
};

QDoubleSpinBox* spin(double minimum, double maximum, int decimals, const QString& suffix,
                     const char* name)
{
    auto* box = new QDoubleSpinBox;
    box->setRange(minimum, maximum);
    box->setDecimals(decimals);
    box->setSuffix(suffix);
    box->setKeyboardTracking(false);
    box->setObjectName(name);
    // Wide ranges would otherwise make the panel wider than its dock.
    box->setMinimumWidth(64);
    return box;
}

QSlider* slider(int minimum, int maximum, const char* name)
{
    auto* s = new QSlider(Qt::Horizontal);
    s->setRange(minimum, maximum);
    s->setObjectName(name);
    return s;
}

QWidget* row(QWidget* a, QWidget* b)
{
    auto* widget = new QWidget;
    auto* layout = new QHBoxLayout(widget);
    layout->setContentsMargins(0, 0, 0, 0);
    layout->addWidget(a, 1);
    layout->addWidget(b, 1);
    return widget;
}

QColor toQColor(const formats::Rgba& c)
{
    return QColor::fromRgbF(float(c.r), float(c.g), float(c.b), float(c.a));
}

} // namespace

PropertiesPanel::PropertiesPanel(Document& document, QWidget* parent)
    : QWidget(parent), m_document(document)
{
    setObjectName("propertiesPanel");
    auto* layout = new QVBoxLayout(this);

    // --- hose -----------------------------------------------------------------------------
    m_hoseGroup = new QGroupBox(tr("Hose"));
    m_hoseGroup->setObjectName("hoseGroup");
    auto* form = new QFormLayout(m_hoseGroup);
    m_name = new QLineEdit;
    m_name->setObjectName("hoseName");
    form->addRow(tr("Name"), m_name);
    m_diameter = spin(0.5, 500, 1, tr(" mm"), "diameter");
    m_diameterSlider = slider(1, 200, "diameterSlider");
    form->addRow(tr("Diameter"), row(m_diameter, m_diameterSlider));
    m_length = spin(0.01, 1000, 3, tr(" m"), "hoseLength");
    m_length->setToolTip(tr("The hose's length at rest. Dragging the hose never changes it; a "
                            "longer hose gets slack between its fixed ends"));
    m_addSlack = new QPushButton(tr("Add 5 % slack"));
    m_addSlack->setObjectName("addSlack");
    m_addSlack->setToolTip(tr("Makes the hose 5 % longer where it lies: the extra length hangs "
                              "between its fixed ends"));
    form->addRow(tr("Length"), row(m_length, m_addSlack));
    m_lengthInfo = new QLabel;
    form->addRow(QString(), m_lengthInfo);
    auto* routePointRow = new QWidget;
    auto* routePointLayout = new QHBoxLayout(routePointRow);
    routePointLayout->setContentsMargins(0, 0, 0, 0);
    for (int i = 0; i < 3; ++i) {
        const char* axis[] = {"X", "Y", "Z"};
        m_routePoint[i] = spin(-1e6, 1e6, 1, tr(" mm"), "");
        m_routePoint[i]->setObjectName(QString("routePoint%1").arg(axis[i]));
        m_routePoint[i]->setPrefix(QString(axis[i]) + " ");
        routePointLayout->addWidget(m_routePoint[i]);
    }
    m_routePointLabel = new QLabel(tr("Route point"));
    form->addRow(m_routePointLabel, routePointRow);
    m_segments = new QSpinBox;
    m_segments->setRange(1, 5000);
    m_segments->setKeyboardTracking(false);
    m_segments->setObjectName("segments");
    m_segmentsSlider = slider(2, 200, "segmentsSlider");
    form->addRow(tr("Resolution (segments)"), row(m_segments, m_segmentsSlider));
    m_colour = new QPushButton;
    m_colour->setObjectName("colour");
    form->addRow(tr("Colour"), m_colour);
    layout->addWidget(m_hoseGroup);

    // --- material -------------------------------------------------------------------------
    m_materialGroup = new QGroupBox(tr("Material"));
    m_materialGroup->setObjectName("materialGroup");
    auto* materialForm = new QFormLayout(m_materialGroup);
    m_preset = new QComboBox;
    m_preset->setObjectName("preset");
    materialForm->addRow(tr("Preset"), m_preset);
    m_expansion = spin(0, 99, 1, tr(" %"), "expansion");
    m_expansionSlider = slider(0, 60, "expansionSlider");
    materialForm->addRow(tr("Expansion"), row(m_expansion, m_expansionSlider));
    m_bendKind = new QComboBox;
    m_bendKind->setObjectName("bendKind");
    m_bendKind->addItems({tr("Minimum bend radius"), tr("Deflection angle")});
    materialForm->addRow(tr("Bend limit"), m_bendKind);
    m_bendValue = spin(0, 5000, 1, QString(), "bendValue");
    m_bendSlider = slider(0, 1000, "bendSlider");
    materialForm->addRow(QString(), row(m_bendValue, m_bendSlider));
    m_savePreset = new QPushButton(tr("Save as preset…"));
    m_savePreset->setObjectName("savePreset");
    materialForm->addRow(QString(), m_savePreset);
    layout->addWidget(m_materialGroup);

    // --- cross-section --------------------------------------------------------------------
    m_profileGroup = new QGroupBox(tr("Cross-section"));
    m_profileGroup->setObjectName("profileGroup");
    auto* profileForm = new QFormLayout(m_profileGroup);
    m_shape = new QComboBox;
    m_shape->setObjectName("shape");
    m_shape->addItems({tr("Circle"), tr("Ellipse"), tr("Rectangle"), tr("Rounded rectangle"),
                       tr("Polygon (from the project file)")});
    // A polygon is shown, not offered: its points are written in the project file.
    if (auto* items = qobject_cast<QStandardItemModel*>(m_shape->model()))
        items->item(kPolygonShapeIndex)->setEnabled(false);
    profileForm->addRow(tr("Shape"), m_shape);
    m_sides = new QSpinBox;
    m_sides->setRange(3, 1024);
    m_sides->setKeyboardTracking(false);
    m_sides->setObjectName("sides");
    profileForm->addRow(tr("Sides"), m_sides);
    m_width = spin(0.1, 1000, 1, tr(" mm"), "profileWidth");
    m_height = spin(0.1, 1000, 1, tr(" mm"), "profileHeight");
    profileForm->addRow(tr("Width × height"), row(m_width, m_height));
    m_cornerRadius = spin(0.0, 500, 2, tr(" mm"), "cornerRadius");
    profileForm->addRow(tr("Corner radius"), m_cornerRadius);
    m_cornerSegments = new QSpinBox;
    m_cornerSegments->setRange(1, 64);
    m_cornerSegments->setKeyboardTracking(false);
    m_cornerSegments->setObjectName("cornerSegments");
    m_cornerSegments->setToolTip(tr("Segments of each rounded corner (1 to 64)"));
    profileForm->addRow(tr("Corner segments"), m_cornerSegments);
    layout->addWidget(m_profileGroup);

    // --- gravity and torsion ----------------------------------------------------
    m_physicsGroup = new QGroupBox(tr("Gravity and torsion"));
    m_physicsGroup->setObjectName("physicsGroup");
    auto* physicsForm = new QFormLayout(m_physicsGroup);
    m_gravity = new QCheckBox(tr("Sags under gravity"));
    m_gravity->setObjectName("gravity");
    m_gravity->setToolTip(tr("The free part of the hose settles under its weight (live in the "
                             "viewport; the route stays as laid out)"));
    m_gravityDirection = new QComboBox;
    m_gravityDirection->setObjectName("gravityDirection");
    for (const auto& [label, direction] : kGravityDirections)
        m_gravityDirection->addItem(
            tr(label), QVariant::fromValue(QVector3D(float(direction.x()), float(direction.y()),
                                                     float(direction.z()))));
    physicsForm->addRow(tr("Gravity"), row(m_gravity, m_gravityDirection));
    m_gravityState = new QLabel;
    m_gravityState->setObjectName("gravityState");
    physicsForm->addRow(QString(), m_gravityState);
    m_torsion = new QCheckBox(tr("Attachments twist the hose"));
    m_torsion->setObjectName("torsion");
    m_twistLimit = spin(0.01, 180.0, 2, tr(" °/joint"), "twistLimit");
    m_twistLimit->setToolTip(tr("Largest twist between neighbouring rings"));
    physicsForm->addRow(tr("Torsion"), row(m_torsion, m_twistLimit));
    layout->addWidget(m_physicsGroup);

    m_message = new QLabel;
    m_message->setObjectName("refusal");
    m_message->setWordWrap(true);
    m_message->setStyleSheet("color: #ff6b5a;");
    layout->addWidget(m_message);

    // --- fixing (fixControls(): placed by the window where scrolling does not move it) ----
    m_fixGroup = new QGroupBox(tr("Fix hose points to a part"));
    m_fixGroup->setObjectName("fixGroup");
    auto* fixForm = new QFormLayout(m_fixGroup);
    m_fixFirst = new QSpinBox;
    m_fixFirst->setObjectName("fixFirst");
    m_fixLast = new QSpinBox;
    m_fixLast->setObjectName("fixLast");
    fixForm->addRow(tr("Axis points"), row(m_fixFirst, m_fixLast));
    m_fixPart = new QLabel(tr("(select a part)"));
    m_fixPart->setMinimumWidth(10);
    m_fixPart->setWordWrap(true);
    fixForm->addRow(tr("Part"), m_fixPart);
    m_fixButton = new QPushButton(tr("Fix to selected part"));
    m_fixButton->setObjectName("fixButton");
    m_fixButton->setToolTip(tr("Fixes the selected hose points to the part shown above"));
    m_pickPartButton = new QPushButton(tr("Fix to part… (Ctrl+F)"));
    m_pickPartButton->setObjectName("pickPartButton");
    m_pickPartButton->setToolTip(tr("Then click the part in the viewport to fix the selected "
                                    "hose points to it (Ctrl+F; Esc cancels)"));
    fixForm->addRow(QString(), row(m_fixButton, m_pickPartButton));
    m_attachments = new QListWidget;
    m_attachments->setObjectName("attachments");
    m_attachments->setMaximumHeight(80);
    fixForm->addRow(tr("Fixed"), m_attachments);
    m_detachButton = new QPushButton(tr("Detach"));
    m_detachButton->setObjectName("detachButton");
    fixForm->addRow(QString(), m_detachButton);

    // --- part -----------------------------------------------------------------------------
    m_partGroup = new QGroupBox(tr("Selected part"));
    m_partGroup->setObjectName("partGroup");
    auto* partForm = new QFormLayout(m_partGroup);
    m_partName = new QLabel;
    m_partName->setWordWrap(true);
    m_partName->setMinimumWidth(10);
    partForm->addRow(m_partName);
    auto* translationRow = new QWidget;
    auto* translationLayout = new QHBoxLayout(translationRow);
    translationLayout->setContentsMargins(0, 0, 0, 0);
    auto* rotationRow = new QWidget;
    auto* rotationLayout = new QHBoxLayout(rotationRow);
    rotationLayout->setContentsMargins(0, 0, 0, 0);
    const char* axes[3] = {"X", "Y", "Z"};
    for (int i = 0; i < 3; ++i) {
        m_translation[i] = spin(-1e6, 1e6, 3, tr(" mm"), "");
        m_translation[i]->setObjectName(QString("partTranslation%1").arg(axes[i]));
        m_translation[i]->setPrefix(QString(axes[i]) + " ");
        translationLayout->addWidget(m_translation[i]);
        m_rotation[i] = spin(-360, 360, 1, tr("°"), "");
        m_rotation[i]->setObjectName(QString("partRotation%1").arg(axes[i]));
        m_rotation[i]->setPrefix(QString(axes[i]) + " ");
        rotationLayout->addWidget(m_rotation[i]);
    }
    partForm->addRow(tr("Position"), translationRow);
    partForm->addRow(tr("Rotation"), rotationRow);
    m_resetPart = new QPushButton(tr("Back to file position"));
    m_resetPart->setObjectName("resetPart");
    partForm->addRow(QString(), m_resetPart);
    m_collider = new QCheckBox(tr("Collider (hoses stay outside it)"));
    m_collider->setObjectName("collider");
    partForm->addRow(QString(), m_collider);
    layout->addWidget(m_partGroup);

    // --- socket ---------------------------------------------------------------------------
    m_socketGroup = new QGroupBox(tr("Selected socket"));
    m_socketGroup->setObjectName("socketGroup");
    auto* socketForm = new QFormLayout(m_socketGroup);
    m_socketName = new QLabel;
    m_socketName->setWordWrap(true);
    m_socketName->setMinimumWidth(10);
    socketForm->addRow(m_socketName);
    m_socketTag = new QLineEdit;
    m_socketTag->setObjectName("socketTag");
    m_socketTag->setToolTip(tr("Hose ends whose plug has this tag fit the socket"));
    socketForm->addRow(tr("Tag"), m_socketTag);
    m_socketRadius = new QLineEdit;
    m_socketRadius->setObjectName("socketRadius");
    m_socketRadius->setToolTip(tr("Capture radius, millimetres > 0: a released hose end this "
                                  "near snaps in"));
    socketForm->addRow(tr("Capture radius (mm)"), m_socketRadius);
    m_socketAngle = new QLineEdit;
    m_socketAngle->setObjectName("socketAngle");
    m_socketAngle->setToolTip(tr("Capture angle, degrees in (0, 180]: how far the end's "
                                 "direction may be off the socket's axis"));
    socketForm->addRow(tr("Capture angle (°)"), m_socketAngle);
    m_deleteSocket = new QPushButton(tr("Delete socket"));
    m_deleteSocket->setObjectName("deleteSocket");
    socketForm->addRow(QString(), m_deleteSocket);
    layout->addWidget(m_socketGroup);
    for (QLineEdit* field : {m_socketTag, m_socketRadius, m_socketAngle})
        connect(field, &QLineEdit::editingFinished, this, [this] {
            if (!m_updating) applySocketFields();
        });
    connect(m_deleteSocket, &QPushButton::clicked, this, [this] {
        const std::string id = m_document.selection().socketId;
        if (m_document.project().findSocket(id))
            m_document.undoStack()->push(makeRemoveSocket(m_document, id));
    });
    layout->addStretch(1);
    watchFields(this);
    watchFields(m_fixGroup);

    // --- wiring ---------------------------------------------------------------------------
    connect(&m_document, &Document::changed, this, &PropertiesPanel::onDocumentChanged);
    auto edit = [this](MergeId id, const QString& text,
                       std::function<void(formats::HoseDefinition&)> change) {
        if (m_updating || m_hoseId.empty()) return;
        formats::HoseDefinition changed = currentDefinition();
        change(changed);
        apply(changed, static_cast<int>(id), text);
    };
    connect(m_name, &QLineEdit::editingFinished, this, [this, edit] {
        if (m_updating) return;
        edit(MergeId::HoseName, tr("Rename hose"),
             [this](formats::HoseDefinition& d) { d.name = m_name->text().toStdString(); });
        m_document.closeMerge();
    });
    connect(m_diameter, &QDoubleSpinBox::valueChanged, this, [this, edit](double mm) {
        if (m_updating) return;
        edit(MergeId::HoseDiameter, tr("Change diameter"),
             [mm](formats::HoseDefinition& d) { d.outerDiameter = mm / 1000.0; });
        m_document.closeMerge();
    });
    connect(m_diameterSlider, &QSlider::valueChanged, this, [edit](int mm) {
        edit(MergeId::HoseDiameter, tr("Change diameter"),
             [mm](formats::HoseDefinition& d) { d.outerDiameter = mm / 1000.0; });
    });
    connect(m_length, &QDoubleSpinBox::valueChanged, this, [this](double metres) {
        if (m_updating) return;
        setHoseLength(metres);
        m_document.closeMerge();
    });
    connect(m_addSlack, &QPushButton::clicked, this, [this] {
        if (const formats::HoseDefinition* definition = m_document.hoseDefinition(m_hoseId)) {
            m_document.closeMerge();
            setHoseLength(1.05 * formats::hoseLength(m_document.project(), *definition));
            m_document.closeMerge();
        }
    });
    // A new resolution carries the fixed points over by arc length (formats::withSegmentCount)
    // in the same step, or is refused saying why.
    const auto setResolution = [this](int n) {
        if (m_updating || m_hoseId.empty()) return;
        formats::HoseDefinition changed;
        try {
            changed = formats::withSegmentCount(m_document.project(), currentDefinition(), n);
        } catch (const std::exception& error) {
            refuse(tr("Refused: %1").arg(QString::fromStdString(error.what())));
            refresh(); // the widgets go back to the document's values
            return;
        }
        apply(changed, static_cast<int>(MergeId::HoseSegments), tr("Change resolution"));
    };
    connect(m_segments, &QSpinBox::valueChanged, this, [this, setResolution](int n) {
        setResolution(n);
        m_document.closeMerge();
    });
    connect(m_segmentsSlider, &QSlider::valueChanged, this, setResolution);
    connect(m_gravity, &QCheckBox::toggled, this, [this, edit](bool on) {
        m_document.closeMerge();
        edit(MergeId::HoseDefinition, on ? tr("Gravity on") : tr("Gravity off"),
             [on](formats::HoseDefinition& d) { d.gravity.enabled = on; });
        m_document.closeMerge();
    });
    connect(m_gravityDirection, &QComboBox::activated, this, [this, edit](int index) {
        if (index < 0 || index >= int(std::size(kGravityDirections)))
            return; // the file's own direction: stays as it is
        const Vec3 v = kGravityDirections[size_t(index)].second;
        m_document.closeMerge();
        edit(MergeId::HoseDefinition, tr("Change gravity direction"),
             [v](formats::HoseDefinition& d) { d.gravity.direction = v; });
        m_document.closeMerge();
    });
    connect(m_torsion, &QCheckBox::toggled, this, [this, edit](bool on) {
        m_document.closeMerge();
        edit(MergeId::HoseDefinition, on ? tr("Torsion on") : tr("Torsion off"),
             [on](formats::HoseDefinition& d) { d.torsion.enabled = on; });
        m_document.closeMerge();
    });
    connect(m_twistLimit, &QDoubleSpinBox::valueChanged, this, [this, edit](double degrees) {
        if (m_updating) return;
        m_document.closeMerge();
        edit(MergeId::HoseDefinition, tr("Change twist limit"),
             [degrees](formats::HoseDefinition& d) {
                 d.torsion.twistLimit = degrees * std::numbers::pi / 180.0;
             });
        m_document.closeMerge();
    });
    connect(&m_document, &Document::gravityStateChanged, this,
            &PropertiesPanel::refreshGravityState);
    connect(m_colour, &QPushButton::clicked, this, [this, edit] {
        const formats::HoseDefinition* definition = m_document.hoseDefinition(m_hoseId);
        if (!definition) return;
        const QColor chosen =
            QColorDialog::getColor(toQColor(definition->colour), this, tr("Hose colour"));
        if (!chosen.isValid()) return;
        edit(MergeId::HoseColour, tr("Change colour"), [chosen](formats::HoseDefinition& d) {
            d.colour = {chosen.redF(), chosen.greenF(), chosen.blueF(), chosen.alphaF()};
        });
        m_document.closeMerge();
    });
    connect(m_preset, &QComboBox::activated, this, [this, edit](int index) {
        if (m_updating) return;
        if (index >= int(m_document.project().materialPresets.size()))
            return; // "custom": stays as it is until a value changes
        const std::string name = m_document.project().materialPresets[size_t(index)].name;
        edit(MergeId::HoseMaterial, tr("Choose material"),
             [name](formats::HoseDefinition& d) { d.material = formats::PresetName{name}; });
        m_document.closeMerge();
    });
    auto materialEdit = [this, edit](bool merge) {
        if (m_updating) return;
        edit(MergeId::HoseMaterial, tr("Change material"),
             [this](formats::HoseDefinition& d) { d.material = currentMaterial(); });
        if (!merge) m_document.closeMerge();
    };
    connect(m_expansion, &QDoubleSpinBox::valueChanged, this, [this, materialEdit](double) {
        if (m_updating) return;
        m_updating = true;
        m_expansionSlider->setValue(int(std::lround(m_expansion->value())));
        m_updating = false;
        materialEdit(false);
    });
    connect(m_expansionSlider, &QSlider::valueChanged, this, [this, materialEdit](int value) {
        if (m_updating) return;
        m_updating = true;
        m_expansion->setValue(value);
        m_updating = false;
        materialEdit(true);
    });
    connect(m_bendKind, &QComboBox::activated, this, [materialEdit](int) { materialEdit(false); });
    connect(m_bendValue, &QDoubleSpinBox::valueChanged, this, [this, materialEdit](double) {
        if (m_updating) return;
        m_updating = true;
        m_bendSlider->setValue(int(std::lround(m_bendValue->value())));
        m_updating = false;
        materialEdit(false);
    });
    connect(m_bendSlider, &QSlider::valueChanged, this, [this, materialEdit](int value) {
        if (m_updating) return;
        m_updating = true;
        m_bendValue->setValue(value);
        m_updating = false;
        materialEdit(true);
    });
    for (QSlider* s : {m_diameterSlider, m_segmentsSlider, m_expansionSlider, m_bendSlider})
        connect(s, &QSlider::sliderReleased, this, &PropertiesPanel::sliderReleased);
    connect(m_savePreset, &QPushButton::clicked, this, [this] {
        if (m_hoseId.empty()) return;
        const QString name = askPresetName ? askPresetName()
                                           : QInputDialog::getText(this, tr("Save material preset"),
                                                                   tr("Preset name:"));
        if (name.trimmed().isEmpty()) return;
        auto presets = m_document.project().materialPresets;
        for (const auto& preset : presets)
            if (preset.name == name.toStdString()) {
                refuse(tr("A preset named '%1' exists already.").arg(name));
                return;
            }
        formats::MaterialPreset preset;
        preset.name = name.toStdString();
        preset.description = "Saved from hose " + m_hoseId;
        preset.material = currentMaterial();
        presets.push_back(preset);
        m_document.undoStack()->push(makeSetPresets(m_document, presets, tr("Save preset")));
    });
    auto profileEdit = [this, edit] {
        if (m_updating || m_shape->currentIndex() == kPolygonShapeIndex) return;
        edit(MergeId::HoseProfile, tr("Change cross-section"), [this](formats::HoseDefinition& d) {
            formats::ProfileSpec p = d.profile;
            const Profile::Shape shapes[] = {Profile::Shape::Circle, Profile::Shape::Ellipse,
                                             Profile::Shape::Rectangle,
                                             Profile::Shape::RoundedRectangle};
            p.shape = shapes[std::clamp(m_shape->currentIndex(), 0, 3)];
            p.sides = m_sides->value();
            p.width = m_width->value() / 1000.0;
            p.height = m_height->value() / 1000.0;
            p.semiAxisX = p.width / 2;
            p.semiAxisY = p.height / 2;
            p.cornerRadius = m_cornerRadius->value() / 1000.0;
            p.cornerSegments = m_cornerSegments->value();
            d.profile = p;
        });
        m_document.closeMerge();
    };
    connect(m_shape, &QComboBox::activated, this, profileEdit);
    connect(m_sides, &QSpinBox::valueChanged, this, profileEdit);
    connect(m_width, &QDoubleSpinBox::valueChanged, this, profileEdit);
    connect(m_height, &QDoubleSpinBox::valueChanged, this, profileEdit);
    connect(m_cornerRadius, &QDoubleSpinBox::valueChanged, this, profileEdit);
    connect(m_cornerSegments, &QSpinBox::valueChanged, this, profileEdit);

    connect(m_fixFirst, &QSpinBox::valueChanged, this, [this](int value) {
        if (m_updating) return;
        Selection selection = m_document.selection();
        selection.rangeFirst = value;
        selection.rangeLast = std::max(value, m_fixLast->value());
        m_document.setSelection(selection);
    });
    connect(m_fixLast, &QSpinBox::valueChanged, this, [this](int value) {
        if (m_updating) return;
        Selection selection = m_document.selection();
        selection.rangeLast = value;
        selection.rangeFirst = std::min(value, m_fixFirst->value());
        m_document.setSelection(selection);
    });
    connect(m_fixButton, &QPushButton::clicked, this, &PropertiesPanel::fixSelectionToPart);
    connect(m_pickPartButton, &QPushButton::clicked, this, &PropertiesPanel::fixToPartRequested);
    for (int i = 0; i < 3; ++i)
        connect(m_routePoint[i], &QDoubleSpinBox::valueChanged, this, [this, i](double mm) {
            const Selection& selection = m_document.selection();
            const formats::HoseDefinition* definition = m_document.hoseDefinition(m_hoseId);
            if (m_updating || !definition || selection.routePoint < 0 ||
                selection.routePoint >= int(definition->route.size()))
                return;
            std::vector<Vec3> route = definition->route;
            route[size_t(selection.routePoint)][i] = mm / 1000.0;
            formats::HoseDefinition changed = *definition;
            changed.route = route;
            const std::string problem = m_document.validateHoseDefinition(changed);
            if (!problem.empty()) {
                refuse(tr("Refused: %1").arg(QString::fromStdString(problem)));
                refresh();
                return;
            }
            m_document.closeMerge();
            m_document.undoStack()->push(makeSetRoute(
                m_document, m_hoseId, route,
                tr("Move route point %1 of %2").arg(selection.routePoint).arg(hoseLabel())));
            m_document.closeMerge();
        });
    connect(m_detachButton, &QPushButton::clicked, this, [this] {
        const int row = m_attachments->currentRow();
        if (m_hoseId.empty() || row < 0) return;
        m_document.undoStack()->push(makeDetach(m_document, m_hoseId, row));
    });

    for (int i = 0; i < 3; ++i) {
        connect(m_translation[i], &QDoubleSpinBox::valueChanged, this,
                [this, i] { setPartTransformFromFields(i); });
        connect(m_rotation[i], &QDoubleSpinBox::valueChanged, this,
                [this] { setPartTransformFromFields(-1); });
    }
    connect(m_collider, &QCheckBox::toggled, this, [this](bool on) {
        const Selection& selection = m_document.selection();
        if (m_updating || !m_document.scene(selection.sceneId) || selection.node < 0 ||
            m_document.isCollider(selection.sceneId, selection.node) == on)
            return;
        m_document.closeMerge();
        m_document.undoStack()->push(
            makeSetCollider(m_document, {selection.sceneId, selection.node}, on));
        m_document.closeMerge();
    });
    connect(m_resetPart, &QPushButton::clicked, this, [this] {
        const Selection& selection = m_document.selection();
        if (!m_document.scene(selection.sceneId) || selection.node < 0) return;
        m_document.closeMerge();
        m_document.undoStack()->push(
            makeSetNodeTransform(m_document, {selection.sceneId, selection.node}, std::nullopt));
        m_document.closeMerge();
    });
    refresh();
}

QString PropertiesPanel::lastRefusal() const
{
    return m_message->text();
}

QString PropertiesPanel::hoseLabel() const
{
    const formats::HoseDefinition* definition = m_document.hoseDefinition(m_hoseId);
    if (!definition) return QString();
    return QString::fromStdString(definition->name.empty() ? definition->id : definition->name);
}

QWidget* PropertiesPanel::fixControls() const
{
    return m_fixGroup;
}

PropertiesPanel::~PropertiesPanel()
{
    if (m_fixGroup && !m_fixGroup->parent()) // never placed by a window
        delete m_fixGroup.data();
}

bool PropertiesPanel::eventFilter(QObject* watched, QEvent* event)
{
    auto* field = qobject_cast<QWidget*>(watched);
    if (!field) return QWidget::eventFilter(watched, event);
    if (event->type() == QEvent::Wheel && !field->hasFocus()) {
        // Over a field it does not edit (only a field with the keyboard focus takes the
        // wheel): the panel scrolls, as anywhere else in it.
        for (QWidget* w = field->parentWidget(); w; w = w->parentWidget())
            if (auto* area = qobject_cast<QAbstractScrollArea*>(w)) {
                QCoreApplication::sendEvent(area->verticalScrollBar(), event);
                break;
            }
        return true;
    }
    if (event->type() == QEvent::ShortcutOverride && !field->property("editing").toBool()) {
        // Ctrl+Z / Ctrl+Y on a field that is not being typed in: the document's undo (the
        // value was entered, so its edit is a document command), not the field's own text
        // undo, which only applies while a value is being typed.
        const auto* key = static_cast<QKeyEvent*>(event);
        if (key->matches(QKeySequence::Undo) || key->matches(QKeySequence::Redo) ||
            (key->key() == Qt::Key_Y && key->modifiers() == Qt::ControlModifier))
            return true; // not accepted: the window's Undo/Redo shortcut runs
    }
    return QWidget::eventFilter(watched, event);
}

void PropertiesPanel::watchFields(QWidget* root)
{
    for (QWidget* field : root->findChildren<QWidget*>()) {
        const bool spinBox = qobject_cast<QAbstractSpinBox*>(field) != nullptr;
        auto* lineEdit = qobject_cast<QLineEdit*>(field);
        const bool inSpinBox = lineEdit && qobject_cast<QAbstractSpinBox*>(field->parentWidget());
        if (inSpinBox) continue; // its spin box is watched
        if (!spinBox && !lineEdit && !qobject_cast<QComboBox*>(field) &&
            !qobject_cast<QSlider*>(field))
            continue;
        field->setFocusPolicy(Qt::StrongFocus); // the wheel gives no focus
        field->installEventFilter(this);
        // "editing" while the author types, until the value is entered (or put back).
        QLineEdit* text = lineEdit ? lineEdit : field->findChild<QLineEdit*>();
        if (!text) continue;
        connect(text, &QLineEdit::textEdited, field,
                [field] { field->setProperty("editing", true); });
        connect(text, &QLineEdit::editingFinished, field,
                [field] { field->setProperty("editing", false); });
        if (auto* box = qobject_cast<QAbstractSpinBox*>(field))
            connect(box, &QAbstractSpinBox::editingFinished, field,
                    [field] { field->setProperty("editing", false); });
    }
}

void PropertiesPanel::fixSelectionToPart()
{
    const Selection& selection = m_document.selection();
    try {
        m_document.undoStack()->push(makeAttach(m_document, selection.hoseId, m_fixFirst->value(),
                                                m_fixLast->value(), selection.sceneId,
                                                selection.node));
        clearRefusal();
    } catch (const std::exception& error) {
        refuse(QString::fromStdString(error.what()));
    }
}

void PropertiesPanel::onDocumentChanged(const ChangeEvent& event)
{
    using Kind = ChangeEvent::Kind;
    switch (event.kind) {
    case Kind::HoseShapeChanged:
        // Only the current-length label depends on the live shape.
        if (event.hoseId == m_hoseId)
            if (const Hose* hose = m_document.hose(m_hoseId))
                m_lengthInfo->setText(tr("axis %1 m now, %2 m at rest")
                                          .arg(hose->currentLength(), 0, 'f', 3)
                                          .arg(hose->restLengthTotal(), 0, 'f', 3));
        break;
    case Kind::PoseChanged:
    case Kind::CollidersChanged:
        refreshPart();
        break;
    case Kind::SocketsChanged:
        refreshSocket();
        break;
    case Kind::FileStateChanged:
        break;
    default:
        refresh();
    }
}

formats::HoseDefinition PropertiesPanel::currentDefinition() const
{
    const formats::HoseDefinition* definition = m_document.hoseDefinition(m_hoseId);
    return definition ? *definition : formats::HoseDefinition();
}

Material PropertiesPanel::currentMaterial() const
{
    Material material;
    material.expansionCoefficient = m_expansion->value() / 100.0;
    if (m_bendKind->currentIndex() == 0)
        material.bendLimit.kind = BendLimit::Kind::MinBendRadius,
        material.bendLimit.value = m_bendValue->value() / 1000.0;
    else
        material.bendLimit.kind = BendLimit::Kind::DeflectionAngle,
        material.bendLimit.value = m_bendValue->value() * std::numbers::pi / 180.0;
    return material;
}

bool PropertiesPanel::apply(const formats::HoseDefinition& changed, int mergeId,
                            const QString& text)
{
    const std::string problem = changed.route.empty() ? std::string("invalid route")
                                                      : m_document.validateHoseDefinition(changed);
    if (!problem.empty()) {
        refuse(tr("Refused: %1").arg(QString::fromStdString(problem)));
        refresh(); // the widgets go back to the document's values
        return false;
    }
    clearRefusal();
    if (changed == currentDefinition()) return true;
    // The history says which hose: "Change diameter of left bracket to valve".
    m_document.undoStack()->push(makeSetHoseDefinition(m_document, m_hoseId, changed,
                                                       static_cast<MergeId>(mergeId),
                                                       tr("%1 of %2").arg(text, hoseLabel())));
    return true;
}

void PropertiesPanel::setHoseLength(double metres)
{
    if (m_hoseId.empty()) return;
    try {
        m_document.undoStack()->push(makeSetHoseLength(m_document, m_hoseId, metres));
        clearRefusal();
    } catch (const std::exception& error) {
        refuse(tr("Refused: %1").arg(QString::fromStdString(error.what())));
        refresh(); // the field goes back to the document's value
    }
}

void PropertiesPanel::refuse(const QString& message)
{
    m_message->setText(message);
    // The field that was edited says it too (the widget whose signal led here, else the one
    // with the keyboard focus), until the next accepted edit.
    QWidget* field = qobject_cast<QWidget*>(sender());
    if (!field || !isAncestorOf(field)) field = QApplication::focusWidget();
    // A spin box's line edit has the focus: the tooltip goes on the spin box.
    while (field && field->parentWidget() && qobject_cast<QAbstractSpinBox*>(field->parentWidget()))
        field = field->parentWidget();
    if (field && isAncestorOf(field)) {
        if (!field->property("toolTipBeforeRefusal").isValid())
            field->setProperty("toolTipBeforeRefusal", field->toolTip());
        const QString before = field->property("toolTipBeforeRefusal").toString();
        field->setToolTip(before.isEmpty() ? message : before + "\n\n" + message);
        m_refusedFields.push_back(field);
    }
    emit statusMessage(message);
}

void PropertiesPanel::clearRefusal()
{
    m_message->clear();
    for (const QPointer<QWidget>& field : m_refusedFields)
        if (field && field->property("toolTipBeforeRefusal").isValid()) {
            field->setToolTip(field->property("toolTipBeforeRefusal").toString());
            field->setProperty("toolTipBeforeRefusal", QVariant());
        }
    m_refusedFields.clear();
}

void PropertiesPanel::sliderReleased()
{
    m_document.closeMerge();
}

void PropertiesPanel::refresh()
{
    m_updating = true;
    const Selection& selection = m_document.selection();
    m_hoseId = m_document.hoseDefinition(selection.hoseId) ? selection.hoseId : std::string();
    const formats::HoseDefinition* definition = m_document.hoseDefinition(m_hoseId);
    for (QWidget* w : std::initializer_list<QWidget*>{m_hoseGroup, m_materialGroup, m_profileGroup,
                                                      m_physicsGroup, m_fixGroup})
        w->setEnabled(definition != nullptr);
    m_preset->clear();
    for (const auto& preset : m_document.project().materialPresets)
        m_preset->addItem(QString::fromStdString(preset.name),
                          QString::fromStdString(preset.description));
    m_preset->addItem(tr("(custom values)"));
    showHoseValues(definition != nullptr);
    if (definition) {
        m_hoseGroup->setTitle(tr("Hose %1").arg(QString::fromStdString(definition->id)));
        m_name->setText(QString::fromStdString(definition->name));
        m_diameter->setValue(definition->outerDiameter * 1000.0);
        m_diameterSlider->setValue(int(std::lround(definition->outerDiameter * 1000.0)));
        try {
            m_length->setValue(formats::hoseLength(m_document.project(), *definition));
        } catch (const std::exception&) {
            m_length->setValue(polylineLength(definition->route)); // cannot be built: see below
        }
        const Hose* hose = m_document.hose(m_hoseId);
        m_lengthInfo->setText(hose ? tr("axis %1 m now, %2 m at rest")
                                         .arg(hose->currentLength(), 0, 'f', 3)
                                         .arg(hose->restLengthTotal(), 0, 'f', 3)
                                   : QString::fromStdString(m_document.hoseBuildError(m_hoseId)));
        const int segments = hose ? hose->segmentCount() : definition->segmentCount;
        m_segments->setValue(segments);
        m_segmentsSlider->setValue(segments);
        const QColor colour = toQColor(definition->colour);
        m_colour->setText(colour.name());
        m_colour->setStyleSheet(
            QString("background-color: %1; color: %2;")
                .arg(colour.name(), colour.lightnessF() > 0.5 ? "black" : "white"));
        Material material;
        try {
            material = m_document.project().materialOf(*definition);
        } catch (const std::exception&) {
        }
        int presetIndex = int(m_document.project().materialPresets.size());
        if (const auto* preset = std::get_if<formats::PresetName>(&definition->material))
            for (size_t i = 0; i < m_document.project().materialPresets.size(); ++i)
                if (m_document.project().materialPresets[i].name == preset->name)
                    presetIndex = int(i);
        m_preset->setCurrentIndex(presetIndex);
        m_expansion->setValue(material.expansionCoefficient * 100.0);
        m_expansionSlider->setValue(int(std::lround(material.expansionCoefficient * 100.0)));
        const bool radius = material.bendLimit.kind == BendLimit::Kind::MinBendRadius;
        m_bendKind->setCurrentIndex(radius ? 0 : 1);
        m_bendValue->setSuffix(radius ? tr(" mm") : tr("°"));
        m_bendValue->setRange(0, radius ? 5000 : 179.9);
        m_bendSlider->setRange(0, radius ? 1000 : 179);
        const double bend = radius ? material.bendLimit.value * 1000.0
                                   : material.bendLimit.value * 180.0 / std::numbers::pi;
        m_bendValue->setValue(bend);
        m_bendSlider->setValue(int(std::lround(bend)));
        const formats::ProfileSpec& p = definition->profile;
        const int shapeIndex = p.shape == Profile::Shape::Ellipse            ? 1
                               : p.shape == Profile::Shape::Rectangle        ? 2
                               : p.shape == Profile::Shape::RoundedRectangle ? 3
                               : p.shape == Profile::Shape::Polygon          ? kPolygonShapeIndex
                                                                             : 0;
        m_shape->setCurrentIndex(shapeIndex);
        m_sides->setValue(p.sides);
        m_width->setValue((shapeIndex == 1 ? 2 * p.semiAxisX : p.width) * 1000.0);
        m_height->setValue((shapeIndex == 1 ? 2 * p.semiAxisY : p.height) * 1000.0);
        m_cornerRadius->setValue(p.cornerRadius * 1000.0);
        m_cornerSegments->setValue(p.cornerSegments);
        // Only the fields the shape is made from can be edited (the others keep their values
        // for when the shape changes).
        // A polygon has none of them: changing one would have turned it into a circle.
        m_sides->setEnabled(shapeIndex <= 1);
        m_width->setEnabled(shapeIndex >= 1 && shapeIndex <= 3);
        m_height->setEnabled(shapeIndex >= 1 && shapeIndex <= 3);
        m_cornerRadius->setEnabled(shapeIndex == 3);
        m_cornerSegments->setEnabled(shapeIndex == 3);
        m_gravity->setChecked(definition->gravity.enabled);
        const Vec3& g = definition->gravity.direction;
        int directionIndex = -1;
        for (size_t i = 0; i < std::size(kGravityDirections); ++i)
            if ((g.normalized() - kGravityDirections[i].second).norm() < 1e-12)
                directionIndex = int(i);
        while (m_gravityDirection->count() > int(std::size(kGravityDirections)))
            m_gravityDirection->removeItem(m_gravityDirection->count() - 1);
        if (directionIndex < 0) { // a direction written by hand: shown, kept unless changed
            m_gravityDirection->addItem(
                tr("(%1, %2, %3)")
                    .arg(g.x(), 0, 'g', 3)
                    .arg(g.y(), 0, 'g', 3)
                    .arg(g.z(), 0, 'g', 3),
                QVariant::fromValue(QVector3D(float(g.x()), float(g.y()), float(g.z()))));
            directionIndex = m_gravityDirection->count() - 1;
        }
        m_gravityDirection->setCurrentIndex(directionIndex);
        m_gravityDirection->setEnabled(definition->gravity.enabled);
        m_torsion->setChecked(definition->torsion.enabled);
        m_twistLimit->setValue(definition->torsion.twistLimit * 180.0 / std::numbers::pi);
        m_twistLimit->setEnabled(definition->torsion.enabled);
        const int points = hose ? hose->pointCount() : 1;
        m_fixFirst->setRange(0, points - 1);
        m_fixLast->setRange(0, points - 1);
        m_fixFirst->setValue(std::max(0, selection.rangeFirst));
        m_fixLast->setValue(std::max(0, selection.rangeLast));
        m_attachments->clear();
        for (const auto& attachment : definition->attachments)
            m_attachments->addItem(QString("[%1, %2] → %3")
                                       .arg(attachment.firstPoint)
                                       .arg(attachment.lastPoint)
                                       .arg(QString::fromStdString(attachment.node)));
        if (m_attachments->count() > 0) m_attachments->setCurrentRow(0);
    } else {
        m_hoseGroup->setTitle(tr("Hose (none selected)"));
        m_attachments->clear();
    }
    const formats::ImportedScene* scene = m_document.scene(selection.sceneId);
    m_fixPart->setText(scene && selection.node >= 0
                           ? QString::fromStdString(scene->nodes[size_t(selection.node)].path)
                           : tr("(select a part)"));
    m_fixButton->setEnabled(definition && scene && selection.node >= 0);
    m_fixButton->setText(
        scene && selection.node >= 0
            ? tr("Fix to %1").arg(QString::fromStdString(scene->nodes[size_t(selection.node)].name))
            : tr("Fix to selected part"));
    m_pickPartButton->setEnabled(definition && selection.rangeFirst >= 0);
    const bool routePoint = definition && selection.routePoint >= 0 &&
                            selection.routePoint < int(definition->route.size());
    const bool routeEditable = routePoint && !m_document.hoseFollowsMovedPart(m_hoseId);
    m_routePointLabel->setText(routePoint ? tr("Route point %1").arg(selection.routePoint)
                                          : tr("Route point"));
    for (int i = 0; i < 3; ++i) {
        m_routePoint[i]->setEnabled(routeEditable);
        m_routePoint[i]->setSpecialValueText(routePoint ? QString() : QStringLiteral(" "));
        m_routePoint[i]->setValue(routePoint
                                      ? definition->route[size_t(selection.routePoint)][i] * 1000.0
                                      : m_routePoint[i]->minimum());
        m_routePoint[i]->setToolTip(routePoint && !routeEditable
                                        ? tr("The hose is fixed to a moved part: its route is "
                                             "kept at the file position")
                                        : tr("Position of the selected route point (world)"));
    }
    m_detachButton->setEnabled(definition && !definition->attachments.empty());
    m_updating = false;
    refreshGravityState();
    refreshPart();
    refreshSocket();
}

void PropertiesPanel::showHoseValues(bool shown)
{
    // With no hose selected the (disabled) fields are blank rather than showing their minimum
    // or the last hose's values: a spin box at its minimum shows its special value text.
    const QString blank = shown ? QString() : QStringLiteral(" ");
    for (QDoubleSpinBox* box : {m_diameter, m_length, m_expansion, m_bendValue, m_width, m_height,
                                m_cornerRadius, m_twistLimit}) {
        box->setSpecialValueText(blank);
        if (!shown) box->setValue(box->minimum());
    }
    for (QSpinBox* box : {m_segments, m_sides, m_cornerSegments, m_fixFirst, m_fixLast}) {
        box->setSpecialValueText(blank);
        if (!shown) box->setValue(box->minimum());
    }
    if (shown) return;
    m_name->clear();
    m_lengthInfo->clear();
    m_colour->setText(QString());
    m_colour->setStyleSheet(QString());
    for (QComboBox* box : {m_preset, m_bendKind, m_shape, m_gravityDirection})
        box->setCurrentIndex(-1);
    for (QSlider* slider : {m_diameterSlider, m_segmentsSlider, m_expansionSlider, m_bendSlider})
        slider->setValue(slider->minimum());
    m_gravity->setChecked(false);
    m_torsion->setChecked(false);
}

void PropertiesPanel::refreshGravityState()
{
    switch (m_document.gravityState(m_hoseId)) {
    case Document::GravityState::Off:
        m_gravityState->clear();
        break;
    case Document::GravityState::Settling:
        m_gravityState->setText(tr("settling…"));
        break;
    case Document::GravityState::Settled:
        m_gravityState->setText(
            tr("settled after %1 steps").arg(m_document.gravitySteps(m_hoseId)));
        break;
    case Document::GravityState::OutOfBudget:
        m_gravityState->setText(tr("still moving after %1 steps: left as it is")
                                    .arg(m_document.gravitySteps(m_hoseId)));
        break;
    }
}

void PropertiesPanel::refreshSocket()
{
    const bool wasUpdating = m_updating;
    m_updating = true;
    const formats::Socket* socket =
        m_document.project().findSocket(m_document.selection().socketId);
    m_socketGroup->setEnabled(socket != nullptr);
    if (socket) {
        m_socketName->setText(
            tr("%1 on %2")
                .arg(QString::fromStdString(socket->id), QString::fromStdString(socket->node)));
        m_socketTag->setText(QString::fromStdString(socket->tag));
        m_socketRadius->setText(QString::number(socket->captureRadius * 1000.0, 'g', 6));
        m_socketAngle->setText(
            QString::number(socket->captureAngle * 180.0 / std::numbers::pi, 'g', 6));
    } else {
        m_socketName->setText(tr("No socket selected (Hose ▸ Add Socket places one)"));
        for (QLineEdit* field : {m_socketTag, m_socketRadius, m_socketAngle})
            field->clear();
    }
    m_updating = wasUpdating;
}

void PropertiesPanel::applySocketFields()
{
    const formats::Socket* current =
        m_document.project().findSocket(m_document.selection().socketId);
    if (!current) return;
    formats::Socket changed = *current;
    changed.tag = m_socketTag->text().trimmed().toStdString();
    bool radiusOk = false, angleOk = false;
    const double radius = QLocale::c().toDouble(m_socketRadius->text().trimmed(), &radiusOk);
    const double angle = QLocale::c().toDouble(m_socketAngle->text().trimmed(), &angleOk);
    if (!radiusOk) {
        refuse(tr("The capture radius must be a number of millimetres > 0"));
        return;
    }
    if (!angleOk) {
        refuse(tr("The capture angle must be a number of degrees in (0, 180]"));
        return;
    }
    // Unchanged in the fields' precision: keep the exact stored value.
    if (QString::number(current->captureRadius * 1000.0, 'g', 6) !=
        m_socketRadius->text().trimmed())
        changed.captureRadius = radius / 1000.0;
    if (QString::number(current->captureAngle * 180.0 / std::numbers::pi, 'g', 6) !=
        m_socketAngle->text().trimmed())
        changed.captureAngle = angle * std::numbers::pi / 180.0;
    if (changed == *current) return;
    const std::string problem = Document::validateSocket(changed);
    if (!problem.empty()) {
        refuse(tr("Refused: %1").arg(QString::fromStdString(problem)));
        return;
    }
    clearRefusal();
    m_document.undoStack()->push(makeSetSocket(m_document, changed));
}

void PropertiesPanel::refreshPart()
{
    const bool wasUpdating = m_updating;
    m_updating = true;
    const Selection& selection = m_document.selection();
    const formats::ImportedScene* scene = m_document.scene(selection.sceneId);
    const bool havePart = scene && selection.node >= 0;
    m_partGroup->setEnabled(havePart);
    const bool hasMesh = havePart && !scene->nodes[size_t(selection.node)].meshes.empty();
    m_collider->setEnabled(hasMesh);
    m_collider->setChecked(havePart && m_document.isCollider(selection.sceneId, selection.node));
    m_collider->setToolTip(havePart && !hasMesh ? tr("This node has no mesh of its own")
                                                : QString());
    if (havePart) {
        m_partName->setText(QString::fromStdString(scene->nodes[size_t(selection.node)].path));
        const formats::Mat4 local =
            m_document.nodeLocalTransform(selection.sceneId, selection.node);
        Mat3 rotation = local.block<3, 3>(0, 0);
        for (int c = 0; c < 3; ++c)
            if (rotation.col(c).norm() > 0) rotation.col(c).normalize();
        const Eigen::Vector3d euler = rotation.eulerAngles(0, 1, 2);
        for (int i = 0; i < 3; ++i) {
            m_translation[i]->setValue(local(i, 3) * 1000.0);
            double degrees = euler[i] * 180.0 / std::numbers::pi;
            if (degrees > 180.0) degrees -= 360.0;
            m_rotation[i]->setValue(degrees);
        }
    } else {
        m_partName->setText(tr("(no part selected)"));
    }
    m_updating = wasUpdating;
}

void PropertiesPanel::setPartTransformFromFields(int translationAxis)
{
    if (m_updating) return;
    const Selection& selection = m_document.selection();
    if (!m_document.scene(selection.sceneId) || selection.node < 0) return;
    const formats::Mat4 current = m_document.nodeLocalTransform(selection.sceneId, selection.node);
    Eigen::Vector3d scale;
    for (int c = 0; c < 3; ++c)
        scale[c] = current.block<3, 1>(0, c).norm();
    const Mat3 rotation = (Eigen::AngleAxisd(m_rotation[0]->value() * std::numbers::pi / 180.0,
                                             Eigen::Vector3d::UnitX()) *
                           Eigen::AngleAxisd(m_rotation[1]->value() * std::numbers::pi / 180.0,
                                             Eigen::Vector3d::UnitY()) *
                           Eigen::AngleAxisd(m_rotation[2]->value() * std::numbers::pi / 180.0,
                                             Eigen::Vector3d::UnitZ()))
                              .toRotationMatrix();
    formats::Mat4 local = current;
    // Only what was edited is taken from the (rounded) fields, so that moving a part along
    // one axis never perturbs the other coordinates or its rotation.
    if (translationAxis < 0)
        local.block<3, 3>(0, 0) = rotation * scale.asDiagonal();
    else
        local(translationAxis, 3) = m_translation[translationAxis]->value() / 1000.0;
    m_document.closeMerge();
    m_document.undoStack()->push(
        makeSetNodeTransform(m_document, {selection.sceneId, selection.node}, local));
    m_document.closeMerge();
}

} // namespace chaintube::editor
