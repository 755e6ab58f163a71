// The counts behind `hairbench reproduce plante2001`: kernels::grid_test_counts against a
// pair-by-pair count of the same scheme (§4.1: shared cell, bounding boxes, then each
// mass in the other's volume), on the wisps of §5.3's short style in motion; the model
// keeps each frame's detection to be counted; and the paper's rows, from a quick run.
#include "harness/paper_setups.h"
#include "harness/reproduce/rows.h"
#include "kernels/plante2001/wisp_grid.h"
#include "models/plante2001/wisp_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>

namespace hairbench {
namespace {

namespace k = kernels;

// The short style's wisps after `frames` frames of shake (the head turning).
k::WispSystem short_style_after(int frames) {
  k::WispSystem s;
  time_plante_style(plante_styles()[0], frames, [&](const plante::WispModel& m) { s = m.wisps(); });
  return s;
}

TEST(ReproducePlante, GridTestCountsAreThePairByPairCounts) {
  const k::WispSystem s = short_style_after(6);
  k::SegmentGrid g;
  k::grid_build(g, s);
  std::vector<std::uint32_t> mailbox(g.size(), ~0u);
  std::vector<k::WispContact> contacts;
  k::grid_contacts_ref(g, s, 0, g.size(), mailbox, contacts);
  const k::GridTestCounts c = k::grid_test_counts(g, contacts);

  k::GridTestCounts want;
  want.segments = g.size();
  std::set<std::pair<std::size_t, std::uint32_t>> touched;  // (segment, other wisp)
  // Whether a mass of segment i's free node is inside segment j's volume.
  auto inside = [&](std::size_t i, std::size_t j) {
    const std::uint32_t node = g.seg[i] + 1;
    if (s.pinned[node]) return false;
    bool any = g.vol[j].contains(s, s.x[node]) >= 0.0f;
    for (int q = 0; q < k::kEnvelopePerSection; ++q)
      any = any || g.vol[j].contains(s, k::envelope_point(s, node, q)) >= 0.0f;
    return any;
  };
  for (std::size_t i = 0; i < g.size(); ++i)
    for (std::size_t j = i + 1; j < g.size(); ++j) {
      if (g.wisp[i] == g.wisp[j] && g.seg[j] - g.seg[i] < 3) {
        ++want.neighbour_pairs;
        continue;
      }
      bool share_cell = true, overlap = true;
      for (int a = 0; a < 3; ++a) {
        share_cell = share_cell && g.cell_lo[i][a] <= g.cell_hi[j][a] && g.cell_lo[j][a] <= g.cell_hi[i][a];
        overlap = overlap && g.lo[i][a] <= g.hi[j][a] && g.lo[j][a] <= g.hi[i][a];
      }
      if (!share_cell) continue;
      ++want.box_tests;
      if (!overlap) continue;
      ++want.box_overlaps;
      want.volume_tests += k::kMassesPerSegment * (!s.pinned[g.seg[i] + 1] + !s.pinned[g.seg[j] + 1]);
      if (!inside(i, j) && !inside(j, i)) continue;
      ++want.intersecting_pairs;
      if (g.wisp[i] == g.wisp[j]) {
        ++want.own_wisp_pairs;
      } else {
        touched.insert({i, g.wisp[j]});
        touched.insert({j, g.wisp[i]});
      }
    }
  want.wisp_contacts = touched.size();

  EXPECT_GT(want.intersecting_pairs, 0u) << "the wisps must touch for the test to mean anything";
  EXPECT_EQ(c.segments, want.segments);
  EXPECT_EQ(c.box_tests, want.box_tests);
  EXPECT_EQ(c.box_overlaps, want.box_overlaps);
  EXPECT_EQ(c.volume_tests, want.volume_tests);
  EXPECT_EQ(c.intersecting_pairs, want.intersecting_pairs);
  EXPECT_EQ(c.own_wisp_pairs, want.own_wisp_pairs);
  EXPECT_EQ(c.wisp_contacts, want.wisp_contacts);
  EXPECT_EQ(c.neighbour_pairs, want.neighbour_pairs);
}

// At §5.3's 24 Hz and frames of 1/24 s, every frame ends with a detection: the grid the
// model shows after a frame is that frame's, and its contacts are among its pairs.
TEST(ReproducePlante, EveryFrameShowsItsOwnDetection) {
  std::vector<float> first_box;
  time_plante_style(plante_styles()[0], 4, [&](const plante::WispModel& m) {
    const k::SegmentGrid& g = m.grid();
    ASSERT_GT(g.size(), 0u);
    first_box.push_back(g.lo[0].x());
    const k::GridTestCounts c = k::grid_test_counts(g, m.contacts());
    EXPECT_GT(c.intersecting_pairs, 0u);
    EXPECT_LE(c.intersecting_pairs, c.box_overlaps);
  });
  ASSERT_EQ(first_box.size(), 4u);
  for (std::size_t f = 1; f < first_box.size(); ++f) EXPECT_NE(first_box[f], first_box[f - 1]) << "frame " << f;
}

TEST(ReproducePlante, QuickRunGivesEveryRow) {
  ReproduceOptions opt;
  opt.frames = 2;
  ThreadPool pool(1);
  const std::function<void(const std::string&)> log = [](const std::string&) {};
  const reproduce::PaperResult r = reproduce::reproduce_plante(reproduce::Ctx{opt, pool, log});
  ASSERT_EQ(r.setups.size(), 9u);
  for (const reproduce::SetupRow& row : r.setups) {
    EXPECT_TRUE(row.matches) << row.id << ": " << row.measured;
    EXPECT_FALSE(row.source.quote.empty()) << row.id;
  }
  // §5.3's segment intersections are set by the paper's grooms, its times by its machine:
  // every number of the section is a measurement.
  EXPECT_TRUE(r.claims.empty());
  ASSERT_EQ(r.measurements.size(), 7u);
  const nlohmann::json pub = reproduce::load_published("plante2001");
  const auto inter = std::ranges::find_if(r.measurements, [](const auto& m) { return m.id == "segment_intersections"; });
  ASSERT_NE(inter, r.measurements.end());
  ASSERT_EQ(inter->columns.size(), 3u);
  for (std::size_t i = 0; i < inter->columns.size(); ++i)
    for (const auto& row : pub["tables"]["section_5_3"]["rows"]) {
      if (row[0] == inter->columns[i]) {
        EXPECT_EQ(inter->published[i], row[3].get<double>()) << inter->columns[i];
      }
    }
  for (const reproduce::MeasurementRow& row : r.measurements) {
    EXPECT_EQ(row.published.size(), row.columns.size()) << row.id;
    EXPECT_EQ(row.measured.size(), row.columns.size()) << row.id;
    for (double v : row.measured) EXPECT_TRUE(std::isfinite(v) && v > 0.0) << row.id;
  }
}

}  // namespace
}  // namespace hairbench
