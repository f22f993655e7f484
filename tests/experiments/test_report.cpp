// report.html: a run's page and a set's page are well-formed HTML (an XML parser
// and libxml2's HTML parser, through xmllint), link every file of the folder (odd
// names included), say why a run failed; `rocklab report` rebuilds the same page
// and refuses a folder that is not a run with exit code 2.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "cli_support.h"
#include "report/html.h"
#include "report/run_report.h"

namespace fs = std::filesystem;
using rocklab::experiments::test::cli;
using rocklab::experiments::test::cliLogged;
using rocklab::experiments::test::scratchDir;
using rocklab::experiments::test::slurp;
using Catch::Contains;

namespace {

const std::string kHopper = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/hopper.toml";

/// What xmllint says about `page` (empty when it is silent); `html` picks libxml2's
/// HTML parser, else the XML one (well-formedness: every element closed, attributes quoted).
std::string xmllint(const fs::path& page, bool html) {
  const fs::path said = page.parent_path() / "xmllint.txt";
  const std::string command = std::string("xmllint --noout ") + (html ? "--html " : "") + "'" + page.string() +
                              "' > '" + said.string() + "' 2>&1";
  const int rc = std::system(command.c_str());
  std::string text = slurp(said);
  fs::remove(said);
  if (rc != 0 && text.empty()) text = "xmllint exited " + std::to_string(rc) + " (installed? scripts/setup.sh installs libxml2-utils)";
  return text;
}

/// libxml2 2.9's HTML parser knows HTML 4 only: "Tag video invalid" and the like
/// for HTML5 elements are not errors of the page; anything else is.
std::string htmlProblems(const fs::path& page) {
  std::istringstream said(xmllint(page, true));
  const std::regex html5_tag(R"(Tag (section|video|source|figure|figcaption|details|summary) invalid)");
  std::string problems, line;
  while (std::getline(said, line)) {
    if (std::regex_search(line, html5_tag)) {
      std::getline(said, line);  // the quoted source line
      std::getline(said, line);  // and its caret
      continue;
    }
    problems += line + "\n";
  }
  return problems;
}

/// Every file under `dir` (the page and its rewrite-in-progress left out) whose link the page lacks.
std::vector<std::string> unlinkedFiles(const fs::path& dir) {
  const std::string page = slurp(dir / "report.html");
  std::vector<std::string> missing;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file() || e.path().filename() == "report.html") continue;
    const fs::path relative = e.path().lexically_relative(dir);
    if (page.find("href=\"" + rocklab::experiments::detail::hrefOf(relative) + "\"") == std::string::npos)
      missing.push_back(relative.string());
  }
  return missing;
}

}  // namespace

TEST_CASE("a run writes report.html: well-formed, every file linked, the movie and stills shown - report rebuilds it",
          "[report]") {
  const fs::path out = scratchDir("report-run");
  fs::create_directories(out);
  const fs::path scene = out / "filmed.toml";
  std::ofstream(scene) << "extends = \"" << kHopper << "\"\n[scene]\nname = \"filmed\"\nend_time = 0.004\n"
                       << "[[cameras]]\nname = \"top\"\nresolution = [160, 120]\nfov_deg = 60.0\nframe_rate = 1000\n"
                          "eye = [0.0, 0.0, 1.5]\ntarget = [0.0, 0.0, 0.3]\nup = [1.0, 0.0, 0.0]\n"
                          "movie = true\nstill_interval = 0.002\n";
  const fs::path run = out / "run";
  REQUIRE(cli({"run", scene.string(), "--out", run.string(), "--quiet", "--set", "particles.0.count=200"}) == 0);
  REQUIRE(fs::exists(run / "report.html"));
  const std::string page = slurp(run / "report.html");

  CHECK(xmllint(run / "report.html", false).empty());
  CHECK(htmlProblems(run / "report.html").empty());
  CHECK(unlinkedFiles(run).empty());
  CHECK_THAT(page, Contains("<span class=\"status\">completed</span>"));
  CHECK_THAT(page, Contains("<h1>rocklab run: filmed</h1>"));
  CHECK_THAT(page, Contains("<td>scene file</td><td>" + scene.string() + "</td>"));  // results.json settings
  CHECK_THAT(page, Contains("<td>end time (s)</td><td>0.004</td>"));
  if (fs::exists(run / "top.mp4")) CHECK_THAT(page, Contains("<source src=\"top.mp4\" type=\"video/mp4\" />"));
  CHECK_THAT(page, Contains("<img src=\"top_still_"));
  CHECK_THAT(page, Contains("Time-step audit"));
  CHECK_THAT(page, Contains("Wall time by stage"));
  CHECK(page.find("http://") == std::string::npos);  // offline: nothing fetched
  CHECK(page.find("https://") == std::string::npos);

  // Files of any name are linked and keep the page well-formed; the rebuilt page equals the run's.
  std::ofstream(run / "a&b <c> \"d\".csv") << "x\n";
  std::ofstream(run / std::string("latin1-\xE9t\xE9.txt")) << "x\n";
  fs::create_directories(run / "sub dir");
  std::ofstream(run / "sub dir" / "n#1?.png") << "x";
  std::string log;
  REQUIRE(cliLogged({"report", run.string()}, log) == 0);
  CHECK_THAT(log, Contains((run / "report.html").string()));
  CHECK(xmllint(run / "report.html", false).empty());
  CHECK(htmlProblems(run / "report.html").empty());
  CHECK(unlinkedFiles(run).empty());
  for (const char* odd : {"a&b <c> \"d\".csv", "sub dir/n#1?.png"}) fs::remove(run / odd);
  fs::remove(run / std::string("latin1-\xE9t\xE9.txt"));
  fs::remove(run / "sub dir");
  fs::remove(run / "report.html");
  REQUIRE(cli({"report", run.string()}) == 0);
  CHECK(slurp(run / "report.html") == page);
  fs::remove_all(out);
}

TEST_CASE("report refuses what is not a run: exit 2 naming the folder and what is missing", "[report]") {
  const fs::path out = scratchDir("report-bad");
  fs::create_directories(out / "empty");
  std::string log;
  CHECK(cliLogged({"report", (out / "empty").string()}, log) == 2);
  CHECK_THAT(log, Contains((out / "empty").string()) && Contains("no results.json"));
  CHECK_FALSE(fs::exists(out / "empty" / "report.html"));

  CHECK(cliLogged({"report", (out / "nowhere").string()}, log) == 2);
  CHECK_THAT(log, Contains((out / "nowhere").string()) && Contains("is not a folder"));

  fs::create_directories(out / "damaged");
  std::ofstream(out / "damaged" / "results.json") << "{\"status\": \"compl";
  CHECK(cliLogged({"report", (out / "damaged").string()}, log) == 2);
  CHECK_THAT(log, Contains((out / "damaged" / "results.json").string()) && Contains("not a JSON object"));
  CHECK_FALSE(fs::exists(out / "damaged" / "report.html"));
  fs::remove_all(out);
}

TEST_CASE("a failed run's page says why, and figures it lacks are shown as absent", "[report]") {
  const fs::path out = scratchDir("report-failed");
  fs::create_directories(out);
  const nlohmann::json r = {{"scene", "chute"},
                            {"status", "watchdog"},
                            {"message", "energy grew by 12 J <beyond> the work of the walls"},
                            {"experiment", "chute"},
                            {"clearance_time_s", nullptr},
                            {"timestep", {{"network_step_ratio_max", 1.3}}}};
  std::ofstream(out / "results.json") << r.dump();
  rocklab::experiments::detail::writeRunReport(out, r);
  const std::string page = slurp(out / "report.html");
  CHECK_THAT(page, Contains("<span class=\"status bad\">watchdog</span>"));
  CHECK_THAT(page, Contains("Run watchdog:</strong> energy grew by 12 J &lt;beyond&gt; the work of the walls"));
  CHECK_THAT(page, Contains("above 1: unstable"));
  CHECK(xmllint(out / "report.html", false).empty());
  fs::remove_all(out);
}

TEST_CASE("a sweep writes one page: its table and plot, linking each run's page", "[report]") {
  const fs::path out = scratchDir("report-sweep");
  REQUIRE(cli({"sweep", kHopper, "--out", out.string(), "--jobs", "0", "--quiet", "--set", "scene.end_time=0.002",
               "--set", "particles.0.count=100", "--vary", "scene.seed=1,2"}) == 0);
  REQUIRE(fs::exists(out / "report.html"));
  const std::string page = slurp(out / "report.html");
  CHECK(xmllint(out / "report.html", false).empty());
  CHECK(htmlProblems(out / "report.html").empty());
  CHECK_THAT(page, Contains("<img src=\"sweep.png\""));
  CHECK_THAT(page, Contains("<a href=\"sweep.csv\">sweep.csv</a>"));
  std::size_t run_pages = 0;
  for (const auto& e : fs::directory_iterator(out / "runs")) {
    REQUIRE(fs::exists(e.path() / "report.html"));
    const fs::path run_page = fs::path("runs") / e.path().filename() / "report.html";
    CHECK_THAT(page, Contains("href=\"" + rocklab::experiments::detail::hrefOf(run_page) + "\""));
    ++run_pages;
  }
  CHECK(run_pages == 2);
  CHECK(unlinkedFiles(out).empty());
  fs::remove_all(out);
}

namespace {

/// What headless Chromium saw on `page` (in its folder, so relative links resolve):
/// "images L/N videos R/M", L images loaded of N, R videos whose MP4 gave its
/// metadata and size of M. A copy of the page with a probe script is opened and removed.
std::string chromiumProbe(const fs::path& page) {
  const fs::path probe_page = page.parent_path() / "report-probe.html", dom = page.parent_path() / "probe-dom.txt";
  std::string html = slurp(page);
  const std::string probe = R"(<script>
window.addEventListener('load', () => setTimeout(() => {
  const imgs = Array.from(document.images), vids = Array.from(document.querySelectorAll('video'));
  const p = document.createElement('pre');
  p.id = 'rocklab-probe';
  p.textContent = 'images ' + imgs.filter(i => i.complete && i.naturalWidth > 0).length + '/' + imgs.length +
      ' videos ' + vids.filter(v => v.readyState >= 1 && !v.error && v.videoWidth > 0).length + '/' + vids.length;
  document.body.appendChild(p);
}, 3000));
</script>
</body>)";
  html.replace(html.rfind("</body>"), 7, probe);
  std::ofstream(probe_page) << html;
  const std::string command = "timeout 120 chromium --headless --no-sandbox --disable-gpu --virtual-time-budget=10000 "
                              "--dump-dom 'file://" + fs::absolute(probe_page).string() + "' > '" + dom.string() +
                              "' 2>/dev/null";
  std::system(command.c_str());
  const std::string text = slurp(dom);
  fs::remove(probe_page);
  fs::remove(dom);
  std::smatch m;
  return std::regex_search(text, m, std::regex(R"(id="rocklab-probe">([^<]*))")) ? m[1].str() : "no probe result";
}

}  // namespace

// Not in CI (label validation): needs Debian's chromium. Opens the demo's page when
// out/demo has one (bash scripts/demo.sh), else a short filmed run's, and saves a screenshot.
TEST_CASE("the page in headless Chromium: the video and every image load - a screenshot", "[report][validation]") {
  REQUIRE(std::system("command -v chromium > /dev/null") == 0);  // apt-get install chromium
  fs::path dir = fs::path(ROCKLAB_SOURCE_DIR) / "out" / "demo";
  const fs::path out = scratchDir("report-chromium");
  if (!fs::exists(dir / "report.html")) {
    fs::create_directories(out);
    std::ofstream(out / "filmed.toml") << "extends = \"" << kHopper << "\"\n[scene]\nname = \"filmed\"\nend_time = 0.004\n"
                                       << "[[cameras]]\nname = \"top\"\nresolution = [320, 240]\nfov_deg = 60.0\n"
                                          "frame_rate = 1000\neye = [0.0, 0.0, 1.5]\ntarget = [0.0, 0.0, 0.3]\n"
                                          "up = [1.0, 0.0, 0.0]\nmovie = true\nstill_interval = 0.002\n";
    dir = out / "run";
    REQUIRE(cli({"run", (out / "filmed.toml").string(), "--out", dir.string(), "--quiet", "--set",
                 "particles.0.count=200"}) == 0);
  }
  const std::string page = slurp(dir / "report.html");
  std::size_t images = 0, videos = 0;
  for (std::size_t at = page.find("<img "); at != std::string::npos; at = page.find("<img ", at + 1)) ++images;
  for (std::size_t at = page.find("<video "); at != std::string::npos; at = page.find("<video ", at + 1)) ++videos;
  REQUIRE(images > 0);
  REQUIRE(videos > 0);
  const std::string all = std::to_string(images) + "/" + std::to_string(images);
  CHECK(chromiumProbe(dir / "report.html") ==
        "images " + all + " videos " + std::to_string(videos) + "/" + std::to_string(videos));

  // The probe sees a broken image: the same page with one image pointing nowhere.
  const fs::path broken = dir / "report-broken.html";
  std::string changed = page;
  changed.replace(changed.find("<img src=\"") + 10, 0, "missing-");
  std::ofstream(broken) << changed;
  CHECK(chromiumProbe(broken).rfind("images " + std::to_string(images - 1) + "/" + std::to_string(images), 0) == 0);
  fs::remove(broken);

  const fs::path shot = out / "report-screenshot.png";
  fs::create_directories(out);
  const std::string command = "timeout 120 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars "
                              "--window-size=1280,1800 --virtual-time-budget=5000 --screenshot='" + shot.string() +
                              "' 'file://" + fs::absolute(dir / "report.html").string() + "' > /dev/null 2>&1";
  std::system(command.c_str());
  CHECK(fs::exists(shot));
  CHECK((fs::exists(shot) && fs::file_size(shot) > 10000));
  WARN("screenshot: " + shot.string());
}
