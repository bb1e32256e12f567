// The route table: every endpoint of the service, one row each, in the order httplib tries them.
// A new endpoint is one handler, one row here and its entry in schemas/api.md's endpoint table
// (tests/station/test_http_routes.cpp checks the rows and the entries are the same set).
#include <regex>
#include <vector>

#include "station/http/http_server.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen headers included after it.
#include <httplib.h>

namespace station::http {

std::span<const HttpServer::Route> HttpServer::route_table() {
  using S = HttpServer;
  static const Route kRoutes[] = {
      {"GET", "/", "/", &S::page},
      {"GET", "/favicon.ico", "/favicon.ico", &S::favicon},
      {"GET", "/static/NAME", R"(/static/([^/]+))", &S::static_file},
      {"GET", "/static/dygraphs/NAME", R"(/static/dygraphs/(dygraph\.min\.(js|css)))",
       &S::dygraphs_file},
      {"GET", "/api/status", "/api/status", &S::get_status},
      {"GET", "/api/live", "/api/live", &S::get_live},
      {"GET", "/api/runs", "/api/runs", &S::list_runs},
      {"GET", "/api/runs/{id}", R"(/api/runs/([^/]+))", &S::get_run},
      {"GET", "/api/runs/{id}/bins", R"(/api/runs/([^/]+)/bins)", &S::get_bins},
      {"GET", "/api/runs/{id}/events", R"(/api/runs/([^/]+)/events)", &S::get_events},
      {"GET", "/api/runs/{id}/acceptance", R"(/api/runs/([^/]+)/acceptance)", &S::get_acceptance},
      {"GET", "/reports/NAME", R"(/reports/([^/]+))", &S::get_report},
      {"GET", "/api/events/stream", "/api/events/stream", &S::event_stream},
      {"POST", "/api/runs", "/api/runs", &S::start_run},
      {"POST", "/api/runs/{id}/stop", R"(/api/runs/([^/]+)/stop)", &S::stop_run},
      {"POST", "/api/runs/{id}/abort", R"(/api/runs/([^/]+)/abort)", &S::abort_run},
      {"POST", "/api/fits/{id}/release", R"(/api/fits/([^/]+)/release)", &S::release_fit},
      {"GET", "/metrics", "/metrics", &S::get_metrics},
  };
  return kRoutes;
}

std::string route_label(const std::string& path) {
  static const auto kPatterns = [] {
    std::vector<std::pair<std::regex, std::string>> out;
    for (const auto& r : HttpServer::route_table()) {
      const bool is_static = std::string_view(r.path).starts_with("/static/");
      out.emplace_back(std::regex(std::string(r.pattern)),
                       is_static ? "/static/*" : std::string(r.path));
    }
    return out;
  }();
  for (const auto& [pattern, label] : kPatterns)
    if (std::regex_match(path, pattern)) return label;
  return "other";
}

void HttpServer::register_routes() {
  for (const auto& r : route_table()) {
    RouteHandler h = [this, fn = r.handler](const httplib::Request& req, httplib::Response& res) {
      (this->*fn)(req, res);
    };
    if (r.method == "POST") {
      post(std::string(r.pattern), std::move(h));
    } else {
      server_->Get(std::string(r.pattern), std::move(h));
    }
  }
}

}  // namespace station::http
