#pragma once
// The colour bar drawn over the 3D view (and into screenshots): the map as a vertical strip with
// tick marks and labels in real units, and the quantity's name and unit as a title.

#include <QColor>
#include <QPainter>
#include <QRectF>
#include <QString>

#include "ColorMap.h"

namespace tp::gui {

QColor toQColor(const Eigen::Vector3f& rgb);

/// Paints the bar into the right-hand side of `viewport` (the whole view), `scale` times the
/// on-screen size (for screenshots larger than the window). Returns the rectangle it used.
QRectF paintColorBar(QPainter& painter, const QRectF& viewport, const ColorMap& map,
                     const QString& title, double scale = 1.0);

}  // namespace tp::gui
