// ChainTube editor — the properties panel: the selected hose's parameters (live while a slider
// moves; one undo step per drag), its material and presets, cross-section, colour, fixing a
// segment to a scene part and detaching, gravity and torsion, and the selected part's
// transform and collider flag. Groups are greyed out when nothing they apply to is selected.
#pragma once

#include "chaintube/editor/document.h"

#include <QPointer>
#include <QWidget>
#include <functional>
#include <vector>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QFormLayout;
class QGroupBox;
class QLabel;
class QLineEdit;
class QListWidget;
class QPushButton;
class QSlider;
class QSpinBox;

namespace chaintube::editor {

class PropertiesPanel : public QWidget
{
    Q_OBJECT
public:
    explicit PropertiesPanel(Document& document, QWidget* parent = nullptr);
    ~PropertiesPanel() override;

    /// The last refusal shown (empty if the last edit was accepted): tests read it.
    QString lastRefusal() const;
    /// Asks for a preset name when saving an own preset; tests replace it.
    std::function<QString()> askPresetName;

    /// Fixes the selected axis-point range of the selected hose to the selected part.
    void fixSelectionToPart();
    /// The "Fix hose points to a part" group: the window places it above the scrolling
    /// panel, so that it stays where it is while the panel scrolls.
    QWidget* fixControls() const;

signals:
    /// "Fix to part…" pressed: the viewport should take the next click on a part.
    void fixToPartRequested();
    /// An edit was refused: why (the main window shows it in the status bar; the panel's
    /// message line and the edited field's tooltip say it too).
    void statusMessage(const QString& message);

protected:
    /// Wheel over a field without the keyboard focus scrolls the panel instead of changing
    /// the value; Ctrl+Z/Ctrl+Y on a field not being typed in go to the document's undo.
    bool eventFilter(QObject* watched, QEvent* event) override;

private:
    void onDocumentChanged(const ChangeEvent& event);
    /// Installs eventFilter() on the editable fields under `root`.
    void watchFields(QWidget* root);
    /// The selected hose's name (its id when it has none), for history texts.
    QString hoseLabel() const;
    void refresh();
    void refreshPart();
    /// Blank (no hose selected) or ready to show a hose's values (see refresh()).
    void showHoseValues(bool shown);
    /// The gravity state label of the selected hose.
    void refreshGravityState();
    /// Makes the selected hose `metres` long (makeSetHoseLength); refuses with a message.
    void setHoseLength(double metres);
    /// Validates `changed` and pushes it as a change of one field; refuses with a message.
    bool apply(const formats::HoseDefinition& changed, int mergeId, const QString& text);
    /// Says why an edit was refused: the message line, the edited field's tooltip and the
    /// status bar (statusMessage()).
    void refuse(const QString& message);
    /// After an accepted edit: the message line cleared, the refused fields' tooltips back.
    void clearRefusal();
    std::vector<QPointer<QWidget>> m_refusedFields;
    void sliderReleased();
    formats::HoseDefinition currentDefinition() const;
    Material currentMaterial() const;
    /// Applies the part fields: translation axis 0–2 changed, or −1 for the rotation.
    void setPartTransformFromFields(int translationAxis);

    Document& m_document;
    bool m_updating = false;
    std::string m_hoseId;

    QGroupBox* m_hoseGroup;
    QLineEdit* m_name;
    QDoubleSpinBox* m_diameter;
    QSlider* m_diameterSlider;
    QDoubleSpinBox* m_length; ///< the hose's length (HoseDefinition::length), metres
    QPushButton* m_addSlack;  ///< length + 5 %
    QLabel* m_lengthInfo;
    QLabel* m_routePointLabel;
    QDoubleSpinBox* m_routePoint[3]; ///< the selected route point, world millimetres
    QSpinBox* m_segments;
    QSlider* m_segmentsSlider;
    QPushButton* m_colour;
    QComboBox* m_preset;
    QDoubleSpinBox* m_expansion;
    QSlider* m_expansionSlider;
    QComboBox* m_bendKind;
    QDoubleSpinBox* m_bendValue;
    QSlider* m_bendSlider;
    QPushButton* m_savePreset;
    QComboBox* m_shape;
    QSpinBox* m_sides;
    QDoubleSpinBox* m_width;
    QDoubleSpinBox* m_height;
    QDoubleSpinBox* m_cornerRadius;
    QSpinBox* m_cornerSegments;
    QGroupBox* m_materialGroup;
    QGroupBox* m_profileGroup;
    /// Gravity and torsion of the hose: HoseDefinition::gravity / ::torsion.
    QGroupBox* m_physicsGroup;
    QCheckBox* m_gravity;          ///< sags live in the viewport
    QComboBox* m_gravityDirection; ///< world axis the hose falls along (−Y = the project's down)
    QLabel* m_gravityState;        ///< settling / settled / out of budget
    QCheckBox* m_torsion;
    QDoubleSpinBox* m_twistLimit; ///< degrees per joint (the model: radians)
    QLabel* m_message;

    /// Placed by the window outside the panel (fixControls()): it may be deleted before it.
    QPointer<QGroupBox> m_fixGroup;
    QSpinBox* m_fixFirst;
    QSpinBox* m_fixLast;
    QLabel* m_fixPart;
    QPushButton* m_fixButton;      ///< fixes to the selected part
    QPushButton* m_pickPartButton; ///< fixes to the part clicked next (fixToPartRequested)
    QListWidget* m_attachments;
    QPushButton* m_detachButton;

    QGroupBox* m_partGroup;
    QLabel* m_partName;
    QDoubleSpinBox* m_translation[3];
    QDoubleSpinBox* m_rotation[3];
    QPushButton* m_resetPart;
    QCheckBox* m_collider; ///< the selected part is a collider (project().colliders)

    /// The selected socket (Selection::socketId): tag, capture radius (mm), capture angle (°).
    QGroupBox* m_socketGroup;
    QLabel* m_socketName;
    QLineEdit* m_socketTag;
    QLineEdit* m_socketRadius;
    QLineEdit* m_socketAngle;
    QPushButton* m_deleteSocket;
    void refreshSocket();
    /// Reads the socket fields; pushes makeSetSocket when they changed, refuses with a message
    /// when Document::validateSocket (or a field that is not a number) says why not.
    void applySocketFields();
};

} // namespace chaintube::editor
