#include "ColorBar.h"

#include <QFontMetricsF>
#include <QLinearGradient>
#include <QObject>
#include <QPolygonF>

#include <algorithm>

namespace tp::gui {

QColor toQColor(const Eigen::Vector3f& rgb) {
  return QColor::fromRgbF(std::clamp(rgb.x(), 0.0f, 1.0f), std::clamp(rgb.y(), 0.0f, 1.0f),
                          std::clamp(rgb.z(), 0.0f, 1.0f));
}

QRectF paintColorBar(QPainter& p, const QRectF& viewport, const ColorMap& map, const QString& title,
                     double scale, double dataLo, double dataHi) {
  p.save();
  p.setRenderHint(QPainter::Antialiasing);
  QFont font = p.font();
  font.setPointSizeF(9.0 * scale);
  p.setFont(font);
  const QFontMetricsF fm(font);

  const double step = map.tickStep();
  const std::vector<double> ticks = map.ticks();
  const double span = map.hi() - map.lo();
  const bool overHigh = dataHi > map.hi() + 1e-9 * span;  // false for NaN
  const bool underLow = dataLo < map.lo() - 1e-9 * span;
  const QString highLabel =
      overHigh ? QObject::tr("max %1").arg(QString::fromStdString(ColorMap::formatTick(dataHi, step / 10)))
               : QString();
  const QString lowLabel =
      underLow ? QObject::tr("min %1").arg(QString::fromStdString(ColorMap::formatTick(dataLo, step / 10)))
               : QString();
  double labelWidth = 0;
  for (double t : ticks)
    labelWidth = std::max(
        labelWidth, fm.horizontalAdvance(QString::fromStdString(ColorMap::formatTick(t, step))));
  const double margin = 10 * scale, barWidth = 16 * scale, tickLength = 5 * scale;
  // An end arrow and its label take 1.5 lines, clear of the end tick's label.
  const double capSpace = 1.5 * fm.height();
  const double barPart = barWidth + tickLength + 4 * scale + labelWidth;
  const double capPart = barWidth + 4 * scale +
                         std::max(fm.horizontalAdvance(highLabel), fm.horizontalAdvance(lowLabel));
  // A long title wraps rather than widen the panel beyond a quarter of the view.
  const double titleLimit = std::max({barPart, capPart, 0.25 * viewport.width()});
  const QRectF titleBounds = fm.boundingRect(QRectF(0, 0, titleLimit, 1e6),
                                             Qt::AlignLeft | Qt::TextWordWrap, title);
  const double barHeight = std::clamp(0.3 * viewport.height(), 50.0 * scale, 280.0 * scale);
  const double width = std::max({barPart, capPart, titleBounds.width()});
  const double caps = (overHigh ? capSpace : 0) + (underLow ? capSpace : 0);
  const QRectF box(viewport.right() - width - 2 * margin, viewport.top() + margin, width + margin,
                   titleBounds.height() + 0.6 * fm.height() + barHeight + caps + 0.6 * fm.height() +
                       margin);

  // A light panel keeps the labels readable over the tissue.
  p.setPen(QPen(QColor(0, 0, 0, 60), 1.0 * scale));
  p.setBrush(QColor(255, 255, 255, 245));
  p.drawRoundedRect(box, 4 * scale, 4 * scale);

  p.setPen(Qt::black);
  const QRectF titleRect(box.left() + 0.5 * margin, box.top() + 0.3 * margin, titleBounds.width(),
                         titleBounds.height());
  p.drawText(titleRect, Qt::AlignLeft | Qt::TextWordWrap, title);

  const double barTop =
      titleRect.bottom() + 0.6 * fm.height() + (overHigh ? capSpace : 0);
  const QRectF bar(box.left() + 0.5 * margin, barTop, barWidth, barHeight);
  QLinearGradient g(bar.bottomLeft(), bar.topLeft());  // low values at the bottom
  for (int i = 0; i <= 16; ++i) g.setColorAt(i / 16.0, toQColor(map.colorAt(i / 16.0)));
  p.setBrush(g);
  p.setPen(QPen(QColor(40, 40, 40), 1.0 * scale));
  p.drawRect(bar);

  // Arrows at the ends where the data go beyond the bar, in the end colour, with the extreme.
  auto cap = [&](bool top, const QString& label) {
    const double y0 = top ? bar.top() - 0.5 * fm.height() : bar.bottom() + 0.5 * fm.height();
    const double y1 = top ? y0 - 0.8 * fm.height() : y0 + 0.8 * fm.height();
    const QPolygonF arrow({QPointF(bar.left(), y0), QPointF(bar.right(), y0),
                           QPointF(bar.center().x(), y1)});
    p.setBrush(toQColor(map.colorAt(top ? 1.0 : 0.0)));
    p.drawPolygon(arrow);
    p.drawText(QRectF(bar.right() + 4 * scale, 0.5 * (y0 + y1) - 0.5 * fm.height(), capPart,
                      fm.height()),
               Qt::AlignLeft | Qt::AlignVCenter, label);
  };
  if (overHigh) cap(true, highLabel);
  if (underLow) cap(false, lowLabel);

  for (double t : ticks) {
    const double y = bar.bottom() - (t - map.lo()) / span * bar.height();
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
