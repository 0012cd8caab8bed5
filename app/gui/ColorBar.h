#pragma once
// The colour bar drawn over the 3D view (and into screenshots): the map as a vertical strip with
// tick marks and labels in real units, and the quantity's name and unit as a title.

#include <QColor>
#include <QPainter>
#include <QRectF>
#include <QString>

#include <limits>

#include "ColorMap.h"

namespace tp::gui {

QColor toQColor(const Eigen::Vector3f& rgb);

/// Paints the bar into the right-hand side of `viewport` (the whole view), `scale` times the
/// on-screen size (for screenshots larger than the window). Returns the rectangle it used. The
/// bar takes at most about a third of the view's height and a quarter of its width (a long
/// title wraps). Values beyond the bar's range (`dataLo`, `dataHi`: the extremes of the data,
/// NaN when unknown) are flagged by an arrow at that end with the extreme value.
QRectF paintColorBar(QPainter& painter, const QRectF& viewport, const ColorMap& map,
                     const QString& title, double scale = 1.0,
                     double dataLo = std::numeric_limits<double>::quiet_NaN(),
                     double dataHi = std::numeric_limits<double>::quiet_NaN());

}  // namespace tp::gui
