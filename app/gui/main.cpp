// tissueprobe: the interactive desktop application.
//   tissueprobe                    the shipped default meristem
//   tissueprobe tissue.ply         a tissue file
//   tissueprobe --session s.json   a saved session
// Units everywhere: µm, MPa, µN.

#include <QApplication>
#include <QTimer>
#include <QCommandLineParser>

#include <clocale>

#include "FileActions.h"
#include "MainWindow.h"
#include "Resources.h"
#include "solver/Memory.h"

int main(int argc, char** argv) {
  // The arguments as given: QApplication removes the ones it knows, and X11 session management
  // takes "-session", which would swallow our --session.
  QStringList arguments;
  for (int i = 0; i < argc; ++i) arguments << QString::fromLocal8Bit(argv[i]);
  tp::keepFreedMemory();
  tp::gui::setDefaultSurfaceFormat();  // before the application object exists
  QApplication app(argc, argv);
  std::setlocale(LC_NUMERIC, "C");  // numbers in files keep a decimal point in every locale
  QApplication::setOrganizationName("TissueProbe");
  QApplication::setApplicationName("TissueProbe");
  QApplication::setApplicationVersion(TP_VERSION);

  QCommandLineParser parser;
  parser.setApplicationDescription(
      "TissueProbe: an AFM-style spherical probe indenting a plant tissue, live.");
  parser.addHelpOption();
  parser.addVersionOption();
  const QCommandLineOption session({"s", "session"}, "Open a saved session (JSON).", "file");
  parser.addOption(session);
  parser.addPositionalArgument("tissue", "Tissue file (PLY); default: the shipped meristem.",
                               "[tissue.ply]");
  parser.process(arguments);

  tp::gui::MainWindow window;
  window.show();
  tp::gui::FileActions* files = window.fileActions();
  if (parser.isSet(session)) {
    QString error;
    if (!files->openSession(parser.value(session), &error)) {
      tp::gui::showError(&window, QObject::tr("Cannot open the session"), error);
      files->openTissue(QString());
    }
  } else if (!parser.positionalArguments().isEmpty()) {
    files->open(parser.positionalArguments().first());
  } else {
    files->openTissue(QString());  // the shipped default tissue
  }
  // Curves a crashed window left in its autosave: asked once the window is up.
  QTimer::singleShot(0, &window, [&window] { window.fileActions()->offerRecovery(); });
  return app.exec();
}
