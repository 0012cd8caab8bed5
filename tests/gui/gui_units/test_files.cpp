// Sessions (JSON round trip, relative tissue paths, errors that name the key) and curves (CSV of
// several curves, nondimensional scales).
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <fstream>

#include "Curves.h"
#include "SessionFile.h"
#include "TestMain.h"
#include "io/CurveCsv.h"

using namespace tp::gui;

namespace {

NamedCurve curve(const std::string& name, double stiffness, bool withFailure) {
  NamedCurve c;
  c.name = name;
  c.site = Eigen::Vector3d(1.25, -3.5, 45.75);
  c.params.youngModulus = 20 + stiffness;
  c.params.pressure = 0.3;
  c.params.bending = tp::BendingModel::Linear;
  for (int k = 0; k <= 4; ++k)
    c.points.push_back({0.1 * k, stiffness * 0.1 * k, 3 + k, 1e-10 * k, true, false});
  c.points.push_back({0.2, stiffness * 0.2 + 1e-13, 2, 3e-11, true, true});  // unloading
  if (withFailure) c.points.push_back({0.5, std::nan(""), 60, 0.3, false, false});
  return c;
}

bool samePoints(const std::vector<tp::CurvePoint>& a, const std::vector<tp::CurvePoint>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    const auto &p = a[i], &q = b[i];
    const bool force = (std::isnan(p.force) && std::isnan(q.force)) || p.force == q.force;
    if (p.depth != q.depth || !force || p.iterations != q.iterations || p.residual != q.residual ||
        p.converged != q.converged || p.unloading != q.unloading)
      return false;
  }
  return true;
}

// The message a session read as "s.json" is refused with (empty when it is accepted).
std::string message(const nlohmann::json& j) {
  try {
    sessionFromJson(j, "s.json");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return {};
}

}  // namespace

class FilesTest : public QObject {
  Q_OBJECT

 private slots:
  void sessionRoundTrip() {
    SessionState s;
    s.tissuePath = "/data/meristem.ply";
    s.params.youngModulus = 3.5;
    s.params.poissonRatio = 0.3;
    s.params.thickness = 0.15;
    s.params.pressure = 0;
    s.params.bending = tp::BendingModel::None;
    s.params.probeRadius = 0.4;
    s.params.autoMesh = false;
    s.params.meshLevel = 2;
    s.params.meshTolerance = 0.05;
    s.params.junctions = tp::JunctionRule::Rigid;
    s.params.junctionBand = true;
    s.schedule.control = tp::Control::Force;
    s.schedule.maxForce = 12.5;
    s.schedule.steps = 7;
    s.schedule.unload = true;
    s.sites = {Eigen::Vector3d(0, 0, 45.8), Eigen::Vector3d(10.5, -2, 40.1)};
    s.currentSite = 1;
    s.curves = {curve("site 1 · E 100 MPa", 60, false), curve("quote \" and, comma", 30, true)};
    s.curves[1].live = true;
    s.curves[0].measured = true;
    // A fit's residuals, one per point (a NaN among them: a point that failed).
    for (size_t k = 0; k < s.curves[1].points.size(); ++k)
      s.curves[1].residuals.push_back(k == 1 ? std::nan("") : 1e-3 * double(k) - 0.0125);
    const SessionState r = sessionFromJson(sessionToJson(s), "test");
    QCOMPARE(r.tissuePath, s.tissuePath);
    QVERIFY(r.params == s.params);
    QVERIFY(r.schedule == s.schedule);
    QCOMPARE(r.currentSite, 1);
    QCOMPARE(int(r.sites.size()), 2);
    QVERIFY(r.sites[1] == s.sites[1]);
    QCOMPARE(int(r.curves.size()), 2);
    for (int i = 0; i < 2; ++i) {
      QCOMPARE(r.curves[i].name, s.curves[i].name);
      QVERIFY(r.curves[i].site == s.curves[i].site);
      QVERIFY(r.curves[i].params == s.curves[i].params);
      QCOMPARE(r.curves[i].live, s.curves[i].live);
      QCOMPARE(r.curves[i].measured, s.curves[i].measured);
      QVERIFY(samePoints(r.curves[i].points, s.curves[i].points));
      QCOMPARE(r.curves[i].residuals.size(), s.curves[i].residuals.size());
      for (size_t k = 0; k < s.curves[i].residuals.size(); ++k)
        QVERIFY(r.curves[i].residuals[k] == s.curves[i].residuals[k] ||
                (std::isnan(r.curves[i].residuals[k]) && std::isnan(s.curves[i].residuals[k])));
    }
    QVERIFY(r.curves[0].residuals.empty());
    QVERIFY(std::isnan(r.curves[1].residuals[1]));
    // Residuals that are not one per point are refused, naming the key.
    nlohmann::json bad = sessionToJson(s);
    bad["curves"][1]["residuals_uN"].erase(0);
    QVERIFY(message(bad).find("curves[1].residuals_uN must be an array of one number per point") !=
            std::string::npos);
    QVERIFY(!r.display);  // none given, none read
  }

  void sessionKeepsHowTheTissueWasShown() {
    SessionState s;
    DisplaySettings d;
    d.quantity = "von_mises_change";
    d.colourMap = "coolwarm";
    d.autoRange = false;
    d.lo = -2.5;
    d.hi = 4.25;
    d.outlines = false;
    d.mesh = true;
    d.glyphs = true;
    d.deformationScale = 20;
    d.section = true;
    d.sectionAxis = 2;
    d.sectionPosition = 0.375;
    d.keepOtherSide = true;
    d.camera = DisplaySettings::Camera{Eigen::Vector3d(1, -2, 40.5),
                                       Eigen::Vector4d(0.5, 0.5, 0.5, 0.5), 12.75};
    s.display = d;
    const SessionState r = sessionFromJson(sessionToJson(s), "test");
    QVERIFY(r.display);
    const DisplaySettings& got = *r.display;
    QCOMPARE(got.quantity, d.quantity);
    QCOMPARE(got.colourMap, d.colourMap);
    QCOMPARE(got.autoRange, false);
    QCOMPARE(got.lo, -2.5);
    QCOMPARE(got.hi, 4.25);
    QCOMPARE(got.outlines, false);
    QCOMPARE(got.mesh, true);
    QCOMPARE(got.glyphs, true);
    QCOMPARE(got.deformationScale, 20.0);
    QCOMPARE(got.section, true);
    QCOMPARE(got.sectionAxis, 2);
    QCOMPARE(got.sectionPosition, 0.375);
    QCOMPARE(got.keepOtherSide, true);
    QVERIFY(got.camera);
    QVERIFY(got.camera->target == d.camera->target);
    QVERIFY((got.camera->orientation - d.camera->orientation).norm() < 1e-15);
    QCOMPARE(got.camera->distance, 12.75);
    // Bad values are refused naming the key.
    const nlohmann::json good = sessionToJson(s);
    QVERIFY(message(good).empty());
    nlohmann::json j = good;
    j["display"]["quantity"] = "colour";
    QVERIFY(message(j).find("display.quantity \"colour\" is not a known quantity") !=
            std::string::npos);
    j = good;
    j["display"]["deformation_scale"] = 500;
    QVERIFY(message(j).find("display.deformation_scale must be a number in [1") !=
            std::string::npos);
    j = good;
    j["display"]["section"]["axis"] = "w";
    QVERIFY(message(j).find("display.section.axis") != std::string::npos);
    j = good;
    j["display"]["camera"]["orientation"] = {0, 0, 0, 0};
    QVERIFY(message(j).find("display.camera.orientation") != std::string::npos);
    j = good;
    j["display"]["colour_map"] = "jet";
    QVERIFY(message(j).find("display.colour_map") != std::string::npos);
    // A quaternion that is not of unit length is normalised when read, and a session read,
    // saved and read again is the same to the bit (normalising a unit quaternion again can move
    // its last bit: fuzz_session found it on CI; [-3, 7, 11, 5] and [1, 2, 3, 4] showed it).
    for (const nlohmann::json& q :
         {nlohmann::json{-3, 7, 11, 5}, nlohmann::json{1, 2, 3, 4}, nlohmann::json{-999, 5, 17, 1}}) {
      j = good;
      j["display"]["camera"]["orientation"] = q;
      const SessionState once = sessionFromJson(j, "s.json");
      QVERIFY(std::abs(once.display->camera->orientation.norm() - 1) < 1e-15);
      const nlohmann::json saved = sessionToJson(once);
      QCOMPARE(sessionToJson(sessionFromJson(saved, "s.json")).dump(), saved.dump());
    }
    // A session without the camera keeps the rest.
    j = good;
    j["display"].erase("camera");
    QVERIFY(!sessionFromJson(j, "s.json").display->camera);
  }

  void sessionKeepsTheStiffnessMap() {
    // A map of three sites, two done (one failed), its parameters and the map quantity shown.
    SessionState s;
    SessionMap m;
    m.plan.tissue = "/data/meristem.ply";
    m.plan.tissueDigest = "V 10, T 20, C 3, fnv 0123";
    for (int k = 0; k < 3; ++k) {
      tp::MapSite site;
      site.kind = k == 2 ? tp::SiteKind::Junction : tp::SiteKind::CellMiddle;
      site.label = "cell " + std::to_string(k);
      site.point = Eigen::Vector3d(k, -k, 40.0 + 1.0 / 3.0);
      m.plan.sites.push_back(site);
    }
    m.params.pressure = 0;
    m.params.youngModulus = 123.5;
    m.results.resize(3);
    m.results[0].task = 0;
    m.results[0].status = "converged";
    m.results[0].secant = 2.0 / 3.0;
    m.results[0].curve = {{0.0, 0.0}, {0.25, 0.1 / 3.0}};
    m.results[2].task = 2;
    m.results[2].status = "failed";
    m.results[2].message = "no contact";
    s.map = m;
    DisplaySettings d;
    d.quantity = "map_hertz";
    s.display = d;
    const SessionState r = sessionFromJson(nlohmann::json::parse(sessionToJson(s).dump()), "t");
    QVERIFY(r.map);
    QCOMPARE(r.map->plan.sites.size(), std::size_t(3));
    QCOMPARE(r.map->plan.sites[1].point, m.plan.sites[1].point);  // bit for bit
    QVERIFY(r.map->plan.sites[2].kind == tp::SiteKind::Junction);
    QCOMPARE(r.map->plan.tissue, m.plan.tissue);
    QCOMPARE(r.map->params.youngModulus, 123.5);
    QCOMPARE(r.map->params.pressure, 0.0);
    QCOMPARE(r.map->results.size(), std::size_t(3));
    QCOMPARE(r.map->results[0].secant, 2.0 / 3.0);
    QCOMPARE(r.map->results[0].curve, m.results[0].curve);
    QCOMPARE(r.map->results[1].task, -1);  // not done
    QCOMPARE(r.map->results[2].message, std::string("no contact"));
    QCOMPARE(r.display->quantity, std::string("map_hertz"));
    QVERIFY(!sessionFromJson(sessionToJson(SessionState{}), "t").map);  // none: none
    // Refused by name: a result of a task the plan does not have, a site without a point.
    nlohmann::json j = sessionToJson(s);
    j["map"]["results"][1]["task"] = 7;
    QVERIFY2(message(j).find("map.results[1]: task 7 is not a task of the plan") != std::string::npos,
             message(j).c_str());
    j = sessionToJson(s);
    j["map"]["plan"]["sites"][0].erase("point");
    QVERIFY2(message(j).find("map.plan") != std::string::npos, message(j).c_str());
    j = sessionToJson(s);
    j["map"]["plan"]["vary"] = {{{"name", "E"}, {"values", {1, 2}}}};
    QVERIFY2(message(j).find("a sweep, not a map") != std::string::npos, message(j).c_str());
    j = sessionToJson(s);
    j["display"]["quantity"] = "map_nothing";
    QVERIFY(message(j).find("not a known quantity") != std::string::npos);
  }

  void sessionFileKeepsTheTissueNextToIt() {
    QTemporaryDir dir;
    SessionState s;
    s.tissuePath = (dir.path() + "/meshes/t.ply").toStdString();
    const std::string path = (dir.path() + "/session.json").toStdString();
    saveSession(path, s);
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    QVERIFY(text.find("\"meshes/t.ply\"") != std::string::npos);  // stored relative
    QCOMPARE(loadSession(path).tissuePath, s.tissuePath);         // read back absolute
  }

  void badSessionsAreRejectedByName() {
    nlohmann::json good = sessionToJson(SessionState{});
    QVERIFY(message(good).empty());
    nlohmann::json j = good;
    j["parameters"]["E_MPa"] = "soft";
    QVERIFY(message(j).find("E_MPa") != std::string::npos);
    j = good;
    j["parameters"]["junction_band"] = "yes";
    QVERIFY(message(j).find("'junction_band' must be true or false") != std::string::npos);
    j = good;
    j["parameters"].erase("junction_band");  // sessions written before it: the default
    QVERIFY(message(j).empty());
    j = good;
    j["format"] = "something";
    QVERIFY(message(j).find("not a TissueProbe session") != std::string::npos);
    j = good;
    j["current_site"] = 3;
    QVERIFY(message(j).find("current_site") != std::string::npos);
    j = good;
    j["curves"] = {{{"name", "c"}, {"points", {{1, 2, 3}}}}};
    QVERIFY(message(j).find("curves[0].points[0]") != std::string::npos);
    QVERIFY(message(j).rfind("s.json", 0) == 0);  // the file is named first
    // Found by fuzz_session: a number JSON cannot hold threw nlohmann's out_of_range past the
    // reader (only parse errors were turned into a message naming the file).
    auto textMessage = [](const std::string& text) {
      try {
        sessionFromText(text, "s.json");
      } catch (const std::runtime_error& e) {
        return std::string(e.what());
      }
      return std::string();
    };
    QCOMPARE(textMessage(R"({"format": "tissueprobe-session", "version": 1, "current_site": 3333e33333})")
                 .rfind("s.json: not valid JSON: ", 0),
             std::size_t(0));
    QVERIFY(textMessage("{\"format\": ").rfind("s.json: not valid JSON: ", 0) == 0);
    // Found by fuzz_session under UBSan: a float where an integer is read (3e11 as the version)
    // was converted to int, undefined behaviour out of range; it, and an integer too large for
    // an int, are now refused naming the key.
    j = good;
    j["version"] = 3e11;
    QVERIFY(message(j).find("unsupported session version") != std::string::npos);
    j = good;
    j["current_site"] = 1e12;
    QVERIFY(message(j).find("'current_site' must be an integer, not 1000000000000.0") !=
            std::string::npos);
    j = good;
    j["schedule"]["steps"] = std::int64_t(1) << 40;
    QVERIFY(message(j).find("'steps' must be an integer, not 1099511627776") != std::string::npos);
    j = good;
    j["parameters"]["mesh"] = std::uint64_t(1) << 63;
    QVERIFY(message(j).find("'mesh' must be an integer") != std::string::npos);
    j = good;
    j["curves"] = {{{"name", "c"}, {"points", {{0.1, 2, 4294967297, 0, true, false}}}}};
    QVERIFY(message(j).find("curves[0].points[0] iterations must be an integer") !=
            std::string::npos);
  }

  void severalCurvesInOneCsv() {
    const std::vector<NamedCurve> curves = {
        curve("site 1 (0.0, 0.0, 45.8) µm · E 100 MPa", 60, false),
        curve("with \"quotes\", commas", 25, true), curve("third", 10, false)};
    const std::string text = curvesCsv(curves);
    // One comment line per curve (its mesh and error), the header, then the points.
    size_t rows = 0, comments = 0;
    for (size_t start = 0; start < text.size();) {
      const size_t end = text.find('\n', start);
      (text[start] == '#' ? comments : rows) += 1;
      start = end + 1;
    }
    QCOMPARE(int(comments), 3);
    QCOMPARE(int(rows), 1 + 6 + 7 + 6);
    QVERIFY(text.find("\ncurve,site_x_um,site_y_um,site_z_um,E_MPa,nu,h_um,p_MPa,"
                      "probe_radius_um,mesh_level,mesh_error,depth_um,force_uN,iterations,"
                      "residual,converged,unloading\n") != std::string::npos);
    // Every row carries its curve's site and parameters (for filtering in a table program).
    {
      const size_t first = text.find("\n\"site 1");
      QVERIFY(first != std::string::npos);
      const std::string row = text.substr(first + 1, text.find('\n', first + 1) - first - 1);
      // Past the quoted name (which has commas of its own): the curve's 10, the point's 6.
      const QStringList cells =
          (QStringLiteral("name,") + QString::fromStdString(row.substr(row.find("\",") + 2)))
              .split(',');
      const NamedCurve& c = curves[0];
      QCOMPARE(cells.size(), 1 + 10 + 6);
      QCOMPARE(cells[1].toDouble(), c.site.x());
      QCOMPARE(cells[3].toDouble(), c.site.z());
      QCOMPARE(cells[4].toDouble(), c.params.youngModulus);
      QCOMPARE(cells[5].toDouble(), c.params.poissonRatio);
      QCOMPARE(cells[7].toDouble(), c.params.pressure);
      QCOMPARE(cells[8].toDouble(), c.params.probeRadius);
      QCOMPARE(cells[9], c.meshLevel >= 0 ? QString::number(c.meshLevel) : QString());
    }
    QVERIFY(text.rfind("# \"site 1 (0.0, 0.0, 45.8) µm · E 100 MPa\": mesh level", 0) == 0);
    const auto back = parseCurvesCsv(text, "curves.csv");
    QCOMPARE(int(back.size()), 3);
    for (int i = 0; i < 3; ++i) {
      QCOMPARE(back[i].first, curves[i].name);
      QVERIFY(samePoints(back[i].second, curves[i].points));
    }
    // A file of an earlier version (no curve columns) still reads.
    std::string old = text;
    const std::string oldHeader = "curve,depth_um,force_uN,iterations,residual,converged,unloading";
    old.replace(old.find("curve,site_x_um"), old.find('\n', old.find("curve,site_x_um")) -
                old.find("curve,site_x_um"), oldHeader);
    for (size_t p = old.find("\n\""); p != std::string::npos; p = old.find("\n\"", p + 1)) {
      size_t after = p + 2;  // past the name's closing quote ("" inside it is a quote) and comma
      while (old[after] != '"' || old[after + 1] == '"') after += old[after] == '"' ? 2 : 1;
      after += 2;
      size_t cut = after;
      for (int k = 0; k < 10; ++k) cut = old.find(',', cut) + 1;
      old.erase(after, cut - after);
    }
    const auto oldBack = parseCurvesCsv(old, "old.csv");
    QCOMPARE(int(oldBack.size()), 3);
    for (int i = 0; i < 3; ++i) QVERIFY(samePoints(oldBack[i].second, curves[i].points));
    // Written atomically to a file, read back the same.
    QTemporaryDir dir;
    const std::string path = (dir.path() + "/curves.csv").toStdString();
    writeCurvesCsv(path, curves);
    std::ifstream in(path);
    QCOMPARE(std::string((std::istreambuf_iterator<char>(in)), {}), text);
  }

  void forcesBelowAPiconewtonReadZero() {
    QCOMPARE(forceText(1.605e-8), std::string("0"));   // first contact: round-off
    QCOMPARE(forceText(-3e-7), std::string("0"));
    QCOMPARE(forceText(4.22717), std::string("4.227"));
    QCOMPARE(forceText(0.0123456), std::string("0.01235"));  // a plasmolysed wall, 10 nN
    QCOMPARE(forceText(2e-6), std::string("2e-06"));
  }

  void curveNamesTellSiteAndParameters() {
    SimulationParams p;
    p.pressure = 0;
    const std::string n = curveName(2, Eigen::Vector3d(1.04, -2, 45.76), p, false);
    QVERIFY(n.find("site 2 (1.0, -2.0, 45.8)") != std::string::npos);
    QVERIFY(n.find("p 0 MPa") != std::string::npos);
    QVERIFY(n.find("E 100 MPa") != std::string::npos);
  }

  void nondimensionalScales() {
    const AxisScale real = axisScale(false, 6, 100);
    QCOMPARE(real.depth, 1.0);
    QCOMPARE(real.force, 1.0);
    const AxisScale nd = axisScale(true, 6, 100);  // L = 6 µm, E = 100 MPa: E L² = 3600 µN
    QVERIFY(std::abs(nd.depth - 1.0 / 6) < 1e-15);
    QVERIFY(std::abs(nd.force - 1.0 / 3600) < 1e-15);
  }
};

TP_GUI_TEST(FilesTest)
#include "test_files.moc"
