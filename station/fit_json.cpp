// Fit coefficients as JSON objects.
#include "station/fit_json.hpp"

namespace station {
namespace {

nlohmann::json keyed(const compensation::FitResult& fit, const std::vector<double>& values) {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < fit.names.size(); ++i) j[fit.names[i]] = values[i];
  return j;
}

}  // namespace

nlohmann::json coefficients_json(const compensation::FitResult& fit) {
  return keyed(fit, fit.coefficients);
}

nlohmann::json std_errors_json(const compensation::FitResult& fit) {
  return keyed(fit, fit.std_errors);
}

nlohmann::json std_errors_hac_json(const compensation::FitResult& fit) {
  return keyed(fit, fit.std_errors_hac);
}

}  // namespace station
