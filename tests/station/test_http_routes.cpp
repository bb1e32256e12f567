// Issue 23 point 12: the HTTP routes are one table; every row is documented in schemas/api.md's
// endpoint table and every documented endpoint is a row, so neither can drift from the other.
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <string>

#include "station/http/http_server.hpp"
#include "text_file.hpp"

namespace sh = station::http;

namespace {

using Endpoint = std::pair<std::string, std::string>;  // method, documented path

/// The rows of api.md's endpoint table: "| GET | `/api/runs/{id}/events?since=N` | …".
std::set<Endpoint> documented_endpoints() {
  const std::regex row(R"(^\| (GET|POST) \| `([^`?]+)[^`]*` \|)");
  std::set<Endpoint> out;
  for (const auto& line :
       station::testing_support::read_lines(std::string(STATION_SOURCE_DIR) + "/schemas/api.md")) {
    std::smatch m;
    if (std::regex_search(line, m, row)) out.insert({m[1].str(), m[2].str()});
  }
  return out;
}

}  // namespace

TEST(HttpRoutes, EveryRouteIsDocumentedAndEveryDocumentedRouteExists) {
  std::set<Endpoint> table;
  for (const auto& r : sh::HttpServer::route_table()) {
    EXPECT_TRUE(r.method == "GET" || r.method == "POST") << r.method << " " << r.path;
    EXPECT_TRUE(r.handler != nullptr) << r.path;
    EXPECT_TRUE(table.insert({std::string(r.method), std::string(r.path)}).second)
        << "twice in the table: " << r.method << " " << r.path;
  }
  const auto docs = documented_endpoints();
  ASSERT_GE(docs.size(), 10u) << "schemas/api.md's endpoint table was not found";
  for (const auto& [method, path] : table)
    EXPECT_TRUE(docs.count({method, path}))
        << method << " " << path << ": no row in schemas/api.md";
  for (const auto& [method, path] : docs)
    EXPECT_TRUE(table.count({method, path}))
        << method << " " << path << ": documented, but not in the route table";
}

TEST(HttpRoutes, EachRowsPatternMatchesItsDocumentedPathWithAnId) {
  // The pattern and the documented path of a row name the same resource: the path with "{id}"
  // as 17 and NAME as a file name matches the pattern, and its label is the documented path.
  for (const auto& r : sh::HttpServer::route_table()) {
    std::string example = std::regex_replace(std::string(r.path), std::regex(R"(\{id\})"), "17");
    example = std::regex_replace(example, std::regex("NAME"), "dygraph.min.js");
    EXPECT_TRUE(std::regex_match(example, std::regex(std::string(r.pattern))))
        << r.path << " vs " << r.pattern;
    const bool is_static = r.path.starts_with("/static/");
    EXPECT_EQ(sh::route_label(example), is_static ? "/static/*" : std::string(r.path));
  }
}

TEST(HttpRoutes, MetricLabelsAreBoundedAndCarryIdsNotNumbers) {
  EXPECT_EQ(sh::route_label("/api/runs/12/bins"), "/api/runs/{id}/bins");
  EXPECT_EQ(sh::route_label("/api/fits/3/release"), "/api/fits/{id}/release");
  EXPECT_EQ(sh::route_label("/api/runs"), "/api/runs");
  EXPECT_EQ(sh::route_label("/static/live.js"), "/static/*");
  EXPECT_EQ(sh::route_label("/api/runs/12/bins/x"), "other");
  EXPECT_EQ(sh::route_label("/etc/passwd"), "other");
  EXPECT_EQ(sh::route_label(""), "other");
}
