#include "ColorBar.h"

#include <QFontMetricsF>
#include <QLinearGradient>

#include <algorithm>

namespace tp::gui {

QColor toQColor(const Eigen::Vector3f& rgb) {
  return QColor::fromRgbF(std::clamp(rgb.x(), 0.0f, 1.0f), std::clamp(rgb.y(), 0.0f, 1.0f),
                          std::clamp(rgb.z(), 0.0f, 1.0f));
}

QRectF paintColorBar(QPainter& p, const QRectF& viewport, const ColorMap& map, const QString& title,
                     double scale) {
  p.save();
  p.setRenderHint(QPainter::Antialiasing);
  QFont font = p.font();
  font.setPointSizeF(9.0 * scale);
  p.setFont(font);
  const QFontMetricsF fm(font);

  const double step = map.tickStep();
  const std::vector<double> ticks = map.ticks();
  double labelWidth = 0;
  for (double t : ticks)
    labelWidth = std::max(
        labelWidth, fm.horizontalAdvance(QString::fromStdString(ColorMap::formatTick(t, step))));
  const double margin = 10 * scale, barWidth = 16 * scale, tickLength = 5 * scale;
  const double titleWidth = fm.horizontalAdvance(title);
  const double barHeight = std::clamp(0.45 * viewport.height(), 60.0 * scale, 320.0 * scale);
  const double width = std::max(barWidth + tickLength + 4 * scale + labelWidth, titleWidth);
  const QRectF box(viewport.right() - width - 2 * margin, viewport.top() + margin, width + margin,
                   barHeight + fm.height() * 2.2 + margin);

  // A light panel keeps the labels readable over the tissue.
  p.setPen(QPen(QColor(0, 0, 0, 60), 1.0 * scale));
  p.setBrush(QColor(255, 255, 255, 245));
  p.drawRoundedRect(box, 4 * scale, 4 * scale);

  p.setPen(Qt::black);
  const QRectF titleRect(box.left() + 0.5 * margin, box.top() + 0.3 * margin, box.width() - margin,
                         fm.height());
  p.drawText(titleRect, Qt::AlignLeft | Qt::AlignVCenter, title);

  const QRectF bar(box.left() + 0.5 * margin, titleRect.bottom() + 0.6 * fm.height(), barWidth,
                   barHeight);
  QLinearGradient g(bar.bottomLeft(), bar.topLeft());  // low values at the bottom
  for (int i = 0; i <= 16; ++i) g.setColorAt(i / 16.0, toQColor(map.colorAt(i / 16.0)));
  p.setBrush(g);
  p.setPen(QPen(QColor(40, 40, 40), 1.0 * scale));
  p.drawRect(bar);

  for (double t : ticks) {
    const double y = bar.bottom() - (t - map.lo()) / (map.hi() - map.lo()) * bar.height();
    p.drawLine(QPointF(bar.right(), y), QPointF(bar.right() + tickLength, y));
    const QString label = QString::fromStdString(ColorMap::formatTick(t, step));
    p.drawText(QRectF(bar.right() + tickLength + 3 * scale, y - fm.height() / 2, labelWidth + 2,
                      fm.height()),
               Qt::AlignLeft | Qt::AlignVCenter, label);
  }
  p.restore();
  return box;
}

}  // namespace tp::gui
