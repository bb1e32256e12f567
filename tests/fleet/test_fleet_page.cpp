// The fleet page's charts (station/fleet/fleet_page): one calibration drawn off the axis with a
// note, and no empty chart of a coefficient the model does not have (issue 35).
#include <gtest/gtest.h>

#include <string>

#include "station/fleet/fleet_charts.hpp"
#include "station/fleet/fleet_page.hpp"

namespace {

using nlohmann::json;
using station::fleet::FleetPoint;

/// The figure JSON the page hands dygraphs, by figure id.
json page_figure(const std::string& page, const std::string& id) {
  const std::string open = "id=\"report-figures\">";
  const auto from = page.find(open);
  if (from == std::string::npos) return nullptr;
  const auto to = page.find("</script>", from);
  for (const auto& f : json::parse(page.substr(from + open.size(), to - from - open.size())))
    if (f["id"] == id) return f;
  return nullptr;
}

TEST(FleetPage, OneCalibrationOfAModelWithoutK0IsOnePointOffTheAxisAndNoK0Chart) {
  FleetPoint p;
  p.fleet_id = 1;
  p.station = "rig-a";
  p.serial = "GX-1";
  p.created_utc = "2026-11-20T00:00:00Z";
  p.part = "GX-200";
  p.terms = "B0+dT";
  p.ref_temp_c = 25;
  p.k1 = 0.002;
  p.b0 = 0.4;
  p.std_ratio = 0.3;
  const std::string page = station::fleet::fleet_html(station::fleet::fleet_charts_json({p}), "all",
                                                      station::report::Assets{});
  // k0: said, not drawn as an empty chart.
  EXPECT_EQ(page.find("data-figure=\"k0-1\""), std::string::npos);
  EXPECT_NE(page.find("data-metric=\"k0\">k0: not a term of model B0+dT"), std::string::npos);
  // k1: its one point in the middle of a range half a place either side, and a note.
  const json k1 = page_figure(page, "k1-1");
  ASSERT_TRUE(k1.is_object());
  EXPECT_EQ(k1["points"], 1);
  EXPECT_EQ(k1["options"]["dateWindow"], json::parse("[0.5, 1.5]"));
  EXPECT_NE(page.find("one calibration: no control limits"), std::string::npos);
}

}  // namespace
