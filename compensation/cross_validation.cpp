#include "compensation/cross_validation.hpp"

#include <cmath>
#include <set>
#include <stdexcept>

namespace station::compensation {
namespace {

/// The bins of `in` whose segment is (keep == true) or is not (keep == false) `seg`.
ModelData select(const ModelInput& in, int seg, bool keep) {
  ModelData d;
  for (std::size_t i = 0; i < in.bias_dph.size(); ++i) {
    if ((in.segment[i] == seg) != keep) continue;
    d.bias_dph.push_back(in.bias_dph[i]);
    d.temp_c.push_back(in.temp_c[i]);
    if (!in.grad_c.empty()) d.grad_c.push_back(in.grad_c[i]);
    if (!in.dtdt_c_per_h.empty()) d.dtdt_c_per_h.push_back(in.dtdt_c_per_h[i]);
    if (!in.channel.empty()) d.channel.push_back(in.channel[i]);
    if (!in.t_s.empty()) d.t_mid_s.push_back(in.t_s[i]);
    d.segment.push_back(in.segment[i]);
  }
  return d;
}

}  // namespace

CrossValidation leave_one_run_out(const ModelInput& in, const ModelSpec& spec) {
  if (in.segment.size() != in.bias_dph.size())
    throw std::invalid_argument("cross-validation: every bin needs its run (segment)");
  const std::set<int> segments(in.segment.begin(), in.segment.end());
  if (segments.size() < 2) throw std::invalid_argument("cross-validation needs two or more runs");
  CrossValidation cv;
  cv.in_sample_rms_dph = fit_model(in, spec).residual_rms_dph;
  double ss = 0;
  std::size_t n = 0;
  for (const int seg : segments) {
    const ModelData train = select(in, seg, false), test = select(in, seg, true);
    const FitResult fit = fit_model(train.view(), spec);
    const std::vector<double> err = compensate(fit, test.view());
    HeldOutRun h{seg, err.size(), 0, sample_std(err)};
    for (const double e : err) h.rms_dph += e * e;
    ss += h.rms_dph;
    n += err.size();
    h.rms_dph = std::sqrt(h.rms_dph / static_cast<double>(err.size()));
    cv.runs.push_back(h);
  }
  cv.pooled_rms_dph = std::sqrt(ss / static_cast<double>(n));
  return cv;
}

}  // namespace station::compensation
