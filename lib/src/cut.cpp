#include "chaintube/cut.h"

#include <algorithm>
#include <string>

namespace chaintube {

namespace {

Hose pieceOf(const Hose& hose, int first, int last)
{
    std::vector<Vec3> points;
    std::vector<double> rest;
    for (int i = first; i <= last; ++i)
        points.push_back(hose.point(i));
    for (int s = first; s < last; ++s)
        rest.push_back(hose.restLength(s));
    HoseSpec spec = hose.spec();
    spec.segmentCount = last - first;
    return Hose::fromAxis(points, rest, spec);
}

} // namespace

CutHose cutHose(const Hose& hose, int point)
{
    const int n = hose.pointCount() - 1;
    if (point <= 0 || point >= n)
        throw InvalidArgument("cut point: expected an interior axis point 1 … " +
                              std::to_string(n - 1) + ", got " + std::to_string(point));
    for (const Hose::Attachment& a : hose.attachments())
        if (point >= a.first && point <= a.last)
            throw InvalidArgument("cut point " + std::to_string(point) + ": held by " +
                                  (a.isClip() ? "clip " : "attachment ") + std::to_string(a.id) +
                                  " (points " + std::to_string(a.first) + " … " +
                                  std::to_string(a.last) + ")");
    double beforeLength = 0.0;
    for (int s = 0; s < point; ++s)
        beforeLength += hose.restLength(s);
    CutHose cut{pieceOf(hose, 0, point), pieceOf(hose, point, n), {}};
    for (const Hose::Attachment& a : hose.attachments()) {
        const bool after = a.first > point;
        Hose& piece = after ? cut.after : cut.before;
        const int offset = after ? point : 0;
        int id = 0;
        if (!a.isClip()) {
            id = piece.attach(a.first - offset, a.last - offset, a.frame);
        } else {
            const double shift = after ? beforeLength : 0.0;
            const double length = piece.restLengthTotal();
            ClipOptions options;
            options.hold = a.hold;
            options.slideMin = std::clamp(a.slideMin - shift, 0.0, length);
            options.slideMax = std::clamp(a.slideMax - shift, options.slideMin, length);
            const double place = std::clamp(a.slide - shift, options.slideMin, options.slideMax);
            id = piece.addClip(place, a.frame, options);
        }
        cut.attachments.push_back({after ? 1 : 0, id});
    }
    return cut;
}

} // namespace chaintube
