#include "FileActions.h"

#include <QFileDialog>
#include <QPainter>
#include <QPdfWriter>
#include <qcustomplot.h>
#include <algorithm>
#include <cmath>
#include <QFileInfo>
#include <QLocale>
#include <QPushButton>
#include <QTimer>
#include <QMessageBox>
#include <QSaveFile>
#include <QSettings>


#include "Autosave.h"
#include "ContactPointDialog.h"
#include "Curves.h"
#include "PlotPanel.h"
#include "RecentFiles.h"
#include "DisplayPanel.h"
#include "MapRunner.h"
#include "ScreenshotDialog.h"
#include "io/TissueFiles.h"
#include "SessionFile.h"
#include "SimulationController.h"
#include "TissueView.h"
#include "io/CurveCsv.h"
#include "io/JpkCurve.h"
#include "io/MeasuredCurve.h"
#include "io/TextFile.h"

namespace tp::gui {

namespace {

QString lastDir() {
  return QSettings().value("lastDirectory").toString();
}
void rememberDir(const QString& file) {
  QSettings().setValue("lastDirectory", QFileInfo(file).absolutePath());
}

}  // namespace

void showError(QWidget* parent, const QString& title, const QString& text) {
  auto* box = new QMessageBox(QMessageBox::Warning, title, text, QMessageBox::Ok, parent);
  box->setObjectName("errorBox");
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->open();  // window-modal, returns at once
}

FileActions::FileActions(QWidget* window, SimulationController* controller, TissueView* view,
                         PlotPanel* plot, DisplayPanel* display, MapRunner* map)
    : QObject(window),
      window_(window),
      controller_(controller),
      view_(view),
      plot_(plot),
      display_(display),
      map_(map) {}

FileActions::~FileActions() = default;

void FileActions::startAutosave() {
  if (autosave_) return;
  autosave_ = std::make_unique<Autosave>();
  auto* timer = new QTimer(this);
  timer->setObjectName("autosaveTimer");
  connect(timer, &QTimer::timeout, this, &FileActions::autosaveNow);
  timer->start(60 * 1000);
}

void FileActions::autosaveNow() {
  if (!autosave_) return;
  const QString path = autosave_->path();
  if (!controller_->hasUnsavedCurves()) {
    autosave_->remove(path);  // saved, exported or cleared: nothing to recover
    return;
  }
  QString error;
  if (!writeSessionCopy(path, &error))  // the last good autosave stays
    emit statusMessage(tr("Autosave failed: %1").arg(error));
}

void FileActions::offerRecovery() {
  if (!autosave_) return;
  const QStringList orphans = autosave_->orphans();
  if (orphans.isEmpty()) return;
  const QString file = orphans.front();
  const QString when = QLocale().toString(Autosave::writtenAt(file), QLocale::ShortFormat);
  QMessageBox box(QMessageBox::Question, tr("Recover the last session?"),
                  tr("TissueProbe did not close normally. Its curves were autosaved at %1.\n\n"
                     "Open them now? (Discard deletes the autosave; Later keeps it for the next "
                     "start.)")
                      .arg(when),
                  QMessageBox::Open | QMessageBox::Discard | QMessageBox::Ignore, window_);
  box.setObjectName("recoverBox");
  box.button(QMessageBox::Ignore)->setText(tr("Later"));
  box.setDefaultButton(QMessageBox::Open);
  const int answer = box.exec();
  if (answer == QMessageBox::Ignore) return;
  if (answer == QMessageBox::Open) {
    QString error;
    if (!openSession(file, &error)) {
      showError(window_, tr("Cannot recover the session"), error);
      return;  // kept: nothing is lost
    }
    controller_->markCurvesUnsaved();  // they are in no file of the user's yet
    emit statusMessage(tr("Recovered the session autosaved at %1; save it to keep it").arg(when));
  }
  autosave_->remove(file);
}

void FileActions::open(const QString& path) {
  if (QFileInfo(path).suffix().compare("json", Qt::CaseInsensitive) == 0) {
    QString error;
    if (!openSession(path, &error)) showError(window_, tr("Cannot open the session"), error);
  } else {
    openTissue(path);
  }
}

void FileActions::openTissue(const QString& path) {
  // Read and checked in the worker; a bad file comes back as SimulationController::loadFailed.
  controller_->loadTissue(path);
  if (!path.isEmpty()) {
    RecentFiles::add(path);
    emit recentFilesChanged();
  }
}

bool FileActions::openSession(const QString& path, QString* error) {
  try {
    const SessionState session = loadSession(path.toStdString());
    if (session.map && map_->running())
      throw std::runtime_error(path.toStdString() +
                               ": holds a stiffness map, and one is running: cancel it first");
    controller_->applySession(session);
    if (session.map)
      map_->setMap(*session.map);
    else
      map_->clear();
    // How it was shown: the dock's settings, and the camera once its tissue is in the view.
    if (session.display) {
      display_->applySettings(*session.display);
      if (session.display->camera) view_->setCameraPose(*session.display->camera);
    }
  } catch (const std::exception& e) {
    if (error) *error = QString::fromUtf8(e.what());
    return false;
  }
  RecentFiles::add(path);
  emit recentFilesChanged();
  return true;
}

bool FileActions::writeSessionCopy(const QString& path, QString* error) {
  try {
    SessionState session = controller_->session();
    if (map_->hasMap()) session.map = map_->map();
    session.display = display_->settings();
    session.display->camera = view_->cameraPose();
    tp::gui::saveSession(path.toStdString(), session);
  } catch (const std::exception& e) {
    if (error) *error = QString::fromUtf8(e.what());
    return false;
  }
  return true;
}

bool FileActions::saveSession(const QString& path, QString* error) {
  if (!writeSessionCopy(path, error)) return false;
  controller_->markCurvesSaved();
  RecentFiles::add(path);
  emit recentFilesChanged();
  return true;
}

bool FileActions::exportCurves(const QString& path, QString* error) {
  try {
    writeCurvesCsv(path.toStdString(), controller_->curves());
  } catch (const std::exception& e) {
    if (error) *error = QString::fromUtf8(e.what());
    return false;
  }
  controller_->markCurvesSaved();
  return true;
}

bool FileActions::exportCurrentCurve(const QString& path, QString* error) {
  const auto& curves = controller_->curves();
  int i = plot_->selectedCurve();
  if (i < 0 || i >= static_cast<int>(curves.size())) i = static_cast<int>(curves.size()) - 1;
  if (i < 0) {
    if (error) *error = tr("There is no curve yet: drag the probe or run a curve first.");
    return false;
  }
  try {
    writeCurveCsv(path.toStdString(), curves[i].points);
  } catch (const std::exception& e) {
    if (error) *error = QString::fromUtf8(e.what());
    return false;
  }
  return true;
}

bool FileActions::exportScreenshot(const QString& path, const QSize& size, QString* error) {
  const QImage image = view_->renderImage(size);
  if (image.isNull()) {
    if (error)
      *error = tr("The 3D view could not be rendered at %1×%2 pixels")
                   .arg(size.width())
                   .arg(size.height());
    return false;
  }
  QSaveFile file(path);
  if (!file.open(QIODevice::WriteOnly) || !image.save(&file, "PNG") || !file.commit()) {
    if (error) *error = tr("%1: %2").arg(path, file.errorString());
    return false;
  }
  return true;
}

bool FileActions::exportFigure(const QString& path, const QSize& size, double dpi, int legend,
                               QString* error) {
  const QString suffix = QFileInfo(path).suffix().toLower();
  if (suffix != "png" && suffix != "pdf") {
    if (error) *error = tr("%1: unknown format '%2' (use .png or .pdf)").arg(path, suffix);
    return false;
  }
  if (size.width() < 64 || size.height() < 32 || !(dpi >= 24 && dpi <= 2400)) {
    if (error)
      *error = tr("%1: a figure of %2×%3 at %4 dpi cannot be drawn")
                   .arg(path)
                   .arg(size.width())
                   .arg(size.height())
                   .arg(dpi);
    return false;
  }
  const auto where = static_cast<PlotPanel::ExportOptions::Legend>(std::clamp(legend, 0, 2));
  // The view takes the left half and the curves the right half of the figure.
  const int left = size.width() / 2, right = size.width() - left, h = size.height();
  const bool pdf = suffix == "pdf";
  // The view is a raster: in a PDF at twice the points, so it stays sharp when printed.
  const QImage view = view_->renderImage(pdf ? QSize(2 * left, 2 * h) : QSize(left, h));
  if (view.isNull()) {
    if (error) *error = tr("The 3D view could not be rendered for the figure");
    return false;
  }
  QSaveFile file(path);
  if (!file.open(QIODevice::WriteOnly)) {
    if (error) *error = tr("%1: %2").arg(path, file.errorString());
    return false;
  }
  bool ok = true;
  if (pdf) {
    QPdfWriter writer(&file);
    writer.setResolution(72);  // one unit = one point
    writer.setPageSize(QPageSize(QSizeF(size), QPageSize::Point, QString(), QPageSize::ExactMatch));
    writer.setPageMargins(QMarginsF(0, 0, 0, 0));
    writer.setCreator(QStringLiteral("TissueProbe"));
    writer.setTitle(tr("TissueProbe figure"));
    QCPPainter painter;
    ok = painter.begin(&writer);
    if (ok) {
      painter.setMode(QCPPainter::pmVectorized);
      painter.setMode(QCPPainter::pmNoCaching);
      painter.drawImage(QRectF(0, 0, left, h), view);
      painter.translate(left, 0);
      plot_->drawInto(&painter, QSize(right, h), where);
      ok = painter.end();
    }
  } else {
    QImage figure(size, QImage::Format_ARGB32);
    figure.fill(Qt::white);
    const double scale = dpi / 96.0;
    {
      QCPPainter painter(&figure);
      painter.setRenderHint(QPainter::Antialiasing);
      painter.drawImage(QPoint(0, 0), view);
      painter.translate(left, 0);
      painter.scale(scale, scale);  // the curves' text and lines drawn for the resolution
      plot_->drawInto(&painter, QSize(int(std::lround(right / scale)), int(std::lround(h / scale))),
                      where);
    }
    ok = savePng(figure, &file, dpi);
  }
  if (!ok || !file.commit()) {
    if (error) *error = tr("%1: could not write the figure (%2)").arg(path, file.errorString());
    return false;
  }
  return true;
}

QString FileActions::askSave(const QString& title, const QString& name, const QString& filter) {
  const QString path = QFileDialog::getSaveFileName(
      window_, title, lastDir().isEmpty() ? name : lastDir() + "/" + name, filter);
  if (!path.isEmpty()) rememberDir(path);
  return path;
}

void FileActions::report(bool ok, const QString& what, const QString& path, const QString& error) {
  if (ok)
    emit statusMessage(tr("Wrote %1 to %2").arg(what, path));
  else
    showError(window_, tr("Cannot write the %1").arg(what), error);
}

void FileActions::openTissueDialog() {
  const QString path = QFileDialog::getOpenFileName(
      window_, tr("Open a tissue"), lastDir(),
      QString::fromStdString(tissueFileFilter()) + tr(";;All files (*)"));
  if (path.isEmpty()) return;
  rememberDir(path);
  openTissue(path);
}

void FileActions::openSessionDialog() {
  const QString path = QFileDialog::getOpenFileName(window_, tr("Open a session"), lastDir(),
                                                    tr("TissueProbe sessions (*.json)"));
  if (path.isEmpty()) return;
  rememberDir(path);
  open(path);
}

bool FileActions::saveSessionDialog() {
  const QString path =
      askSave(tr("Save the session"), "session.json", tr("TissueProbe sessions (*.json)"));
  if (path.isEmpty()) return false;
  QString error;
  const bool ok = saveSession(path, &error);
  report(ok, tr("session"), path, error);
  return ok;
}

void FileActions::exportPlotDialog() {
  const QString path = askSave(tr("Export the plot"), "curves.png",
                               tr("PNG image (*.png);;SVG drawing (*.svg);;PDF document (*.pdf)"));
  if (path.isEmpty()) return;
  // A figure's size, not the dock's (704×237 on a 1280×800 window): 3:2 by default.
  const bool vector = !path.endsWith(".png", Qt::CaseInsensitive);
  ScreenshotDialog dialog(vector ? QSize(540, 360) : QSize(1200, 800), tr("Size of the plot"),
                          vector ? tr(" pt") : tr(" px"), window_);
  if (!vector) dialog.addResolution(96);
  dialog.addLegendChoice();
  if (dialog.exec() != QDialog::Accepted) return;
  QString error;
  PlotPanel::ExportOptions options;
  options.width = dialog.imageSize().width();
  options.height = dialog.imageSize().height();
  options.dpi = dialog.resolution();
  options.legend = static_cast<PlotPanel::ExportOptions::Legend>(dialog.legendChoice());
  report(plot_->exportImage(path, options, &error), tr("plot"), path, error);
}

void FileActions::exportCurvesDialog() {
  const QString path = askSave(tr("Export every curve"), "curves.csv", tr("CSV (*.csv)"));
  if (path.isEmpty()) return;
  QString error;
  report(exportCurves(path, &error), tr("curves"), path, error);
}

void FileActions::exportCurrentCurveDialog() {
  const QString path = askSave(tr("Export the curve"), "curve.csv", tr("CSV (*.csv)"));
  if (path.isEmpty()) return;
  QString error;
  report(exportCurrentCurve(path, &error), tr("curve"), path, error);
}

void FileActions::exportFigureDialog() {
  const QString path = askSave(tr("Export a figure: the 3D view and the curves"), "figure.png",
                               tr("PNG image (*.png);;PDF document (*.pdf)"));
  if (path.isEmpty()) return;
  const bool pdf = path.endsWith(".pdf", Qt::CaseInsensitive);
  ScreenshotDialog dialog(pdf ? QSize(720, 320) : QSize(1800, 800), tr("Size of the figure"),
                          pdf ? tr(" pt") : tr(" px"), window_);
  if (!pdf) dialog.addResolution(96);
  dialog.addLegendChoice();
  if (dialog.exec() != QDialog::Accepted) return;
  QString error;
  report(exportFigure(path, dialog.imageSize(), dialog.resolution(), dialog.legendChoice(), &error),
         tr("figure"), path, error);
}

void FileActions::exportScreenshotDialog() {
  ScreenshotDialog dialog(view_->size() * view_->devicePixelRatioF(), window_);
  if (dialog.exec() != QDialog::Accepted) return;
  const QString path = askSave(tr("Save a screenshot"), "tissue.png", tr("PNG image (*.png)"));
  if (path.isEmpty()) return;
  QString error;
  report(exportScreenshot(path, dialog.imageSize(), &error), tr("screenshot"), path, error);
}

bool FileActions::importMeasuredCurve(const QString& path, QString* error,
                                      std::optional<double> contactHeight) {
  try {
    const std::string text = readTextFile(path.toStdString(), "curve");
    NamedCurve c;
    const QString file = QFileInfo(path).fileName();
    MeasuredCurve m;
    if (looksLikeJpkText(text)) {
      RawCurveOptions options;
      options.contactHeight = contactHeight;
      const RawCurveReading r = parseJpkForceCurve(text, path.toStdString(), options);
      m = r.curve;
      c.name = tr("measured · %1 (contact at %2 µm%3)")
                   .arg(file)
                   .arg(r.contactHeight, 0, 'f', contactHeight ? 4 : 2)
                   .arg(contactHeight ? tr(", chosen") : QString())
                   .toStdString();
    } else {
      m = parseMeasuredCurve(text, path.toStdString());
      c.name = tr("measured · %1").arg(file).toStdString();
    }
    for (size_t k = 0; k < m.depth.size(); ++k)
      c.points.push_back(CurvePoint{m.depth[k], m.force[k], 0, 0.0, true, false});
    c.site = controller_->latest().site;
    controller_->addMeasuredCurve(std::move(c));
  } catch (const std::exception& e) {
    if (error) *error = QString::fromUtf8(e.what());
    return false;
  }
  return true;
}

void FileActions::importMeasuredCurveDialog() {
  const QString path = QFileDialog::getOpenFileName(
      window_, tr("Import a measured curve"), QString(),
      tr("Force curves (*.csv *.tsv *.txt *.dat);;All files (*)"));
  if (path.isEmpty()) return;
  QString error;
  // A raw JPK curve: its contact point shown, and moved if the user wants, before it is converted.
  std::optional<double> contact;
  try {
    const std::string text = readTextFile(path.toStdString(), "curve");
    if (looksLikeJpkText(text)) {
      ContactPointDialog dialog(parseJpkForceCurve(text, path.toStdString()),
                                QFileInfo(path).fileName(), window_);
      if (dialog.exec() != QDialog::Accepted) return;
      if (dialog.moved()) contact = dialog.contactHeight();
    }
  } catch (const std::exception&) {
    // importMeasuredCurve reads it again and names the problem.
  }
  if (!importMeasuredCurve(path, &error, contact)) {
    showError(window_, tr("Cannot read the curve"), error);
    return;
  }
  emit statusMessage(tr("Measured curve %1 added").arg(QFileInfo(path).fileName()));
}

bool FileActions::exportMapTable(const QString& path, QString* error) {
  try {
    map_->exportTable(path);
  } catch (const std::exception& e) {
    if (error) *error = QString::fromUtf8(e.what());
    return false;
  }
  return true;
}

bool FileActions::exportMapSurface(const QString& path, QString* error) {
  try {
    map_->exportSurface(path);
  } catch (const std::exception& e) {
    if (error) *error = QString::fromUtf8(e.what());
    return false;
  }
  return true;
}

void FileActions::exportMapTableDialog() {
  if (!map_->hasMap()) {
    showError(window_, tr("No stiffness map"), tr("Make one first: Simulation ▸ Stiffness map."));
    return;
  }
  const QString path = askSave(tr("Export the stiffness map"), "map.csv", tr("CSV (*.csv)"));
  if (path.isEmpty()) return;
  QString error;
  report(exportMapTable(path, &error), tr("stiffness map"), path, error);
}

void FileActions::exportMapSurfaceDialog() {
  if (!map_->hasMap()) {
    showError(window_, tr("No stiffness map"), tr("Make one first: Simulation ▸ Stiffness map."));
    return;
  }
  const QString path = askSave(tr("Export the stiffness map's surface"), "map-surface.vtu",
                               tr("VTK unstructured grid (*.vtu)"));
  if (path.isEmpty()) return;
  QString error;
  report(exportMapSurface(path, &error), tr("stiffness map surface"), path, error);
}

void FileActions::exportVtuDialog() {
  const QString path =
      askSave(tr("Export the deformed state"), "state.vtu", tr("VTK unstructured grid (*.vtu)"));
  if (path.isEmpty()) return;
  controller_->exportVtu(path);  // written by the worker, which owns the state
}

}  // namespace tp::gui
