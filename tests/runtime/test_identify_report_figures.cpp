// The report's SVG figures: balanced tags, one marker per plotted point and ticks covering the
// data (PCA scores, validation, routing), and the SVG module's nice ticks against hand values.
#include "report_test_support.hpp"

namespace {

using namespace symoro::study;
namespace svg = symoro::svg;
using namespace symoro::test::report;
namespace fs = std::filesystem;

// --- Nice ticks -----------------------------------------------------------------------------

TEST(SvgPlot, NiceTicksMatchHandValues) {
  auto expect = [](double lo, double hi, int n, double step, int decimals, std::vector<double> values) {
    const svg::Ticks t = svg::nice_ticks(lo, hi, n);
    EXPECT_DOUBLE_EQ(t.step, step) << lo << " " << hi;
    EXPECT_EQ(t.decimals, decimals) << lo << " " << hi;
    ASSERT_EQ(t.values.size(), values.size()) << lo << " " << hi;
    for (std::size_t i = 0; i < values.size(); ++i) EXPECT_DOUBLE_EQ(t.values[i], values[i]) << lo << " " << hi;
  };
  expect(0, 10, 5, 2, 0, {0, 2, 4, 6, 8, 10});
  expect(-3.2, 7.9, 5, 2, 0, {-4, -2, 0, 2, 4, 6, 8});  // raw 2.22 -> 2
  expect(0.013, 0.087, 5, 0.01, 2, {0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09});
  expect(120, 980, 4, 200, 0, {0, 200, 400, 600, 800, 1000});     // raw 215 -> 200
  expect(-1e-4, 3e-4, 5, 1e-4, 4, {-1e-4, 0, 1e-4, 2e-4, 3e-4});  // raw 8e-5 -> 1e-4
  expect(0.3, 0.7, 4, 0.1, 1, {0.3, 0.4, 0.5, 0.6, 0.7});         // 0.3/0.1 is 2.99..96
  expect(7.9, -3.2, 5, 2, 0, {-4, -2, 0, 2, 4, 6, 8});            // reversed bounds
  // Exactly representable: 0.3 must be the double nearest 0.3, not 3 * 0.1.
  EXPECT_EQ(svg::nice_ticks(0.3, 0.7, 4).values[0], 0.3);
}

TEST(SvgPlot, DegenerateRangesStillCoverTheValue) {
  for (double v : {5.0, 0.0, -1e-5, 1e6}) {
    const svg::Ticks t = svg::nice_ticks(v, v, 5);
    ASSERT_GE(t.values.size(), 2u) << v;
    EXPECT_LE(t.values.front(), v);
    EXPECT_GE(t.values.back(), v);
    EXPECT_GT(t.step, 0);
  }
  const svg::Ticks t = svg::nice_ticks(std::nan(""), 1, 5);
  EXPECT_DOUBLE_EQ(t.values.front(), 0);
  EXPECT_DOUBLE_EQ(t.values.back(), 1);
}

TEST(SvgPlot, TickTextNeverShowsMinusZero) {
  EXPECT_EQ(svg::tick_text(-1e-17, 2), "0.00");
  EXPECT_EQ(svg::tick_text(-0.0, 0), "0");
  EXPECT_EQ(svg::tick_text(-0.25, 2), "-0.25");
  EXPECT_EQ(svg::tick_text(1000, 0), "1000");
}

TEST(SvgPlot, RendersOneMarkerPerFinitePointAndEscapesText) {
  svg::Figure f;
  f.title = "a <b> & \"c\"";
  svg::Panel p;
  svg::Series s;
  s.name = "pts";
  s.x = {0, 1, 2, std::nan(""), 4};
  s.y = {1, -2, 3, 4, 100};
  for (auto m :
       {svg::Marker::circle, svg::Marker::square, svg::Marker::triangle, svg::Marker::diamond, svg::Marker::cross}) {
    s.style.marker = m;
    p.points.push_back(s);
  }
  svg::Series line;
  line.x = {0, 1, std::nan(""), 3, 4};
  line.y = {0, 1, 2, 3, 4};
  p.lines.push_back(line);
  p.labels.push_back({4, 100, "x<y", true, "#000"});
  f.panels = {p, p};
  const std::string out = svg::render(f);
  EXPECT_TRUE(balanced(out));
  EXPECT_EQ(count(out, "class=\"marker\""), 2u * 5 * 4);  // NaN pair left out
  EXPECT_EQ(count(out, "class=\"legend-marker\""), 1u);   // one entry per name
  EXPECT_EQ(count(out, "<polyline"), 2u * 2);             // the NaN breaks the line
  EXPECT_EQ(count(out, "class=\"ring\""), 2u);
  EXPECT_NE(out.find("a &lt;b&gt; &amp; &quot;c&quot;"), std::string::npos);
  EXPECT_NE(out.find(">x&lt;y</text>"), std::string::npos);
  for (const auto& panel : panels(out)) {
    const auto xt = tick_values(panel, "xtick"), yt = tick_values(panel, "ytick");
    ASSERT_FALSE(xt.empty());
    EXPECT_LE(xt.front(), 0);
    EXPECT_GE(xt.back(), 4);
    EXPECT_LE(*std::min_element(yt.begin(), yt.end()), -2);
    EXPECT_GE(*std::max_element(yt.begin(), yt.end()), 100);
  }
}

TEST_F(Report, PcaFigureHasOneMarkerPerScoreAndCoveringTicks) {
  const std::string svg = read_text(*dir_ / "figures" / "pca_clouds.svg");
  EXPECT_TRUE(balanced(svg));
  const auto& pca = study().pca;
  const Eigen::MatrixXd* stages[] = {&pca.ols, &pca.sdp, &pca.clie};
  const auto ps = panels(svg);
  ASSERT_EQ(ps.size(), 3u);
  std::size_t total = 0;
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (int s = 0; s < 3; ++s) {
    std::size_t finite = 0;
    for (int i = 0; i < stages[s]->rows(); ++i)
      if (stages[s]->row(i).allFinite()) {
        ++finite;
        for (int c = 0; c < 2; ++c)
          lo[c] = std::min(lo[c], (*stages[s])(i, c)), hi[c] = std::max(hi[c], (*stages[s])(i, c));
      }
    EXPECT_EQ(count(ps[s], "class=\"marker\""), finite) << s;
    total += finite;
    // The representative ringed and labelled, AP01 labelled at every interval.
    EXPECT_EQ(count(ps[s], "class=\"ring\""), 1u);
    EXPECT_EQ(count(ps[s], ">AG02@40ms</text>"), 1u);
    for (const char* id : {"AP01@10ms", "AP01@20ms", "AP01@40ms", "AP01@80ms"})
      EXPECT_EQ(count(ps[s], std::string(">") + id + "</text>"), 1u) << id;
  }
  EXPECT_EQ(total, 3 * study().runs.size() - 1);  // the failed run has no CLIE score
  EXPECT_EQ(count(svg, "class=\"marker\""), total);
  // Shared axes: every panel's ticks cover all three stages' scores.
  for (const auto& p : ps) {
    const auto xt = tick_values(p, "xtick"), yt = tick_values(p, "ytick");
    ASSERT_GE(xt.size(), 2u);
    ASSERT_GE(yt.size(), 2u);
    EXPECT_LE(xt.front(), lo[0]);
    EXPECT_GE(xt.back(), hi[0]);
    EXPECT_LE(*std::min_element(yt.begin(), yt.end()), lo[1]);
    EXPECT_GE(*std::max_element(yt.begin(), yt.end()), hi[1]);
    EXPECT_EQ(tick_values(p, "xtick"), tick_values(ps[0], "xtick"));
  }
  for (const char* legend : {">10 ms<", ">20 ms<", ">40 ms<", ">80 ms<"}) EXPECT_EQ(count(svg, legend), 1u) << legend;
  EXPECT_EQ(count(svg, "class=\"legend-marker\""), 4u);
}

TEST_F(Report, ValidationFigureStacksTheChosenJoints) {
  const std::string svg = read_text(*dir_ / "figures" / "validation_V03.svg");
  EXPECT_TRUE(balanced(svg));
  const auto ps = panels(svg);
  ASSERT_EQ(ps.size(), 3u);
  const ValidationRecord& v = study().validation[2];
  const int joints[] = {1, 3, 5};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NE(ps[k].find(">J" + std::to_string(joints[k] + 1) + "</text>"), std::string::npos);
    EXPECT_EQ(count(ps[k], "<polyline"), 3u);  // measured, CLIE, rescue
    EXPECT_EQ(count(ps[k], "<polyline class=\"line\" fill=\"none\" stroke=\"#000000\""), 1u);
    const double lo = std::min({v.tau_measured.col(joints[k]).minCoeff(), v.tau_clie.col(joints[k]).minCoeff(),
                                v.tau_rescue.col(joints[k]).minCoeff()});
    const double hi = std::max({v.tau_measured.col(joints[k]).maxCoeff(), v.tau_clie.col(joints[k]).maxCoeff(),
                                v.tau_rescue.col(joints[k]).maxCoeff()});
    const auto yt = tick_values(ps[k], "ytick"), xt = tick_values(ps[k], "xtick");
    EXPECT_LE(*std::min_element(yt.begin(), yt.end()), lo);
    EXPECT_GE(*std::max_element(yt.begin(), yt.end()), hi);
    EXPECT_LE(xt.front(), 0);
    EXPECT_GE(xt.back(), v.time(v.time.size() - 1));
    // Every sample is a vertex of the measured line.
    const auto start = ps[k].find("points=\"", ps[k].find("stroke=\"#000000\""));
    const std::string points = ps[k].substr(start + 8, ps[k].find('"', start + 8) - start - 8);
    EXPECT_EQ(count(points, ","), static_cast<std::size_t>(v.time.size()));
  }
}

TEST_F(Report, RoutingFigureHasOneBarPerRouteAndInterval) {
  const std::string svg = read_text(*dir_ / "figures" / "routing.svg");
  EXPECT_TRUE(balanced(svg));
  EXPECT_EQ(count(svg, "class=\"bar\""), 2 * kIntervals.size());
  for (const char* c : {">10 ms<", ">20 ms<", ">40 ms<", ">80 ms<"}) EXPECT_EQ(count(svg, c), 1u) << c;
}

}  // namespace
