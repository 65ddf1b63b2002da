// ChainTube — how hard a hose pulls on what holds it: per attachment, after an update.
#pragma once

#include "chaintube/hose.h"

namespace chaintube {

/// The hose's pull on one attachment (or clip), as a platform reads it after an update to hold
/// a part back or drive haptics. The model has no forces: the pull is derived from the shape.
///
/// Each side of the attachment along the hose whose free span ends at another pinned point (an
/// attachment, a clip, the held point) pulls along its first free segment, away from the
/// attachment. Its *tautness* says how straight the span is drawn: with chord c between its two
/// pins and rest length L (the sum of its segments' rest lengths), 0 while c ≤ (1 − w)·L,
/// rising linearly to 1 at c = L, where w = kTautWindow; 1 whenever an attachment of the span
/// is beyond reach (Hose::attachmentGap() > 0). A side that ends at a free end is slack (0).
/// Its *strain* is the span's stretch beyond its rest length, relative (c − L can only exceed 0
/// on a stretchable hose), plus the gap of an unmet attachment over L. Its force, given the
/// hose's axial stiffness EA (newtons per unit strain), is tautness · EA · strain: zero while
/// slack, growing as the hose is drawn beyond its length.
struct AttachmentPull
{
    /// Unit world direction of the net pull on the attachment (its sides' pulls summed, each
    /// along its first free segment weighted by tautness · max(strain, kTautStrainFloor)): the
    /// way the hose draws the part. Zero when every side is slack.
    Vec3 direction = Vec3::Zero();
    /// The largest tautness of its sides, 0 … 1.
    double tautness = 0.0;
    /// The largest strain of its taut sides (≥ 0, dimensionless).
    double strain = 0.0;
    /// The net pull for an axial stiffness of 1 N per unit strain (world, newtons): its sides'
    /// tautness · strain along their first free segments, summed as vectors.
    Vec3 pullPerStiffness = Vec3::Zero();
    /// The net pull (world, newtons) for the hose's axial stiffness EA (newtons per unit
    /// strain, ≥ 0; a rubber hose of 20 mm about 1e4 N, a steel-braided one 1e6 N); zero for a
    /// negative or non-finite EA.
    Vec3 force(double axialStiffness) const;
};

/// The fraction w of a span's rest length below which its chord counts as slack (tautness 0).
inline constexpr double kTautWindow = 0.02;
/// A taut side's weight in the direction when its strain is 0 (an inextensible hose drawn
/// straight pulls along itself even though it cannot stretch).
inline constexpr double kTautStrainFloor = 1e-9;

/// The pull of `hose` on attachment `id` (an id attach() or addClip() returned), from its shape
/// now. Unknown id: every field zero. O(length of its spans).
AttachmentPull attachmentPull(const Hose& hose, int id);

} // namespace chaintube
