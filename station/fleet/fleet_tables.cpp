#include "station/fleet/fleet_tables.hpp"

#include <stdexcept>
#include <string>

namespace station::fleet {
namespace {

// The station that recorded a fit: the station of the first run it used (fits have no station
// column of their own; a fit of runs no longer in the file falls back to :station).
// The item's revision: its outbox `changes` in the same snapshot (migration 007).
#define STATION_REV(item, id) \
  "(SELECT o.changes FROM fleet_outbox AS o WHERE o.item = '" item "' AND o.local_id = " id ")"

#define STATION_FIT_STATION(f)                   \
  "coalesce((SELECT r.station FROM json_each(" f \
  ".runs_json) AS j JOIN runs AS r ON r.id = "   \
  "j.value ORDER BY r.id LIMIT 1), :station)"

const std::vector<FleetTable> kTables = {
    {"runs", Item::run,
     "rev,uuid,station,local_id,started_utc,ended_utc,state,protocol_name,protocol_text,config_"
     "text,"
     "software_version,operator,sim_seed,step_index,step_started_s,t_s,recording,record_start_s,"
     "start_temp_c,t0_wall_s,resolved_json",
     "uuid",
     "SELECT " STATION_REV("run", "runs.id") ", uuid, station, id, started_utc, ended_utc, state, "
                                             "protocol_name, protocol_text, "
                                             "config_text, software_version, operator, sim_seed, "
                                             "step_index, step_started_s, t_s, "
                                             "recording, record_start_s, start_temp_c, t0_wall_s, "
                                             "resolved_json FROM runs WHERE id = :id",
     Merge::upsert},
    {"run_slots", Item::run,
     "run_uuid,slot,node,serial,pulse_weight_arcsec,axis,earth_rate_dph,part_number,"
     "part_limits_json,gyro_source",
     "run_uuid,slot",
     "SELECT r.uuid, s.slot, s.node, s.serial, s.pulse_weight_arcsec, s.axis, s.earth_rate_dph, "
     "s.part_number, s.part_limits_json, s.gyro_source FROM run_slots AS s JOIN runs AS r ON r.id "
     "= s.run_id "
     "WHERE s.run_id = :id",
     Merge::replace_set},
    {"bins", Item::run,
     "run_uuid,serial,t_start_s,n,rate_dph,bias_dph,temp_c,grad_c,dtdt_c_per_h,complete,"
     "temp_min_c,temp_max_c,grad_min_c,grad_max_c",
     "run_uuid,serial,t_start_s",
     "SELECT r.uuid, b.serial, b.t_start_s, b.n, b.rate_dph, b.bias_dph, b.temp_c, b.grad_c, "
     "b.dtdt_c_per_h, b.complete, b.temp_min_c, b.temp_max_c, b.grad_min_c, b.grad_max_c "
     "FROM bins AS b JOIN runs AS r ON r.id = b.run_id "
     "WHERE b.run_id = :id",
     Merge::replace_set},
    // Issue 36: the run's acceptance figures (station migrations 12 and 13, fleet version 6); a
    // recomputation replaces them, a serial no longer computed is deleted.
    {"acceptance_results", Item::run,
     "run_uuid,serial,computed_utc,part_number,pass,sf_pulse_per_arcsec,sf_se_pulse_per_arcsec,"
     "sf_temp_c,tc_ppm_per_c,tc_se_ppm_per_c,nonlinearity_max_ppm_fs,asymmetry_ppm,"
     "asymmetry_se_ppm,tilt_mrad,tilt_se_mrad,turn_on_repeatability_dph,"
     "turn_on_repeatability_lower_dph,turn_on_repeatability_upper_dph,max_warmup_s,figures_json",
     "run_uuid,serial",
     "SELECT r.uuid, a.serial, a.computed_utc, a.part_number, a.pass, a.sf_pulse_per_arcsec, "
     "a.sf_se_pulse_per_arcsec, a.sf_temp_c, a.tc_ppm_per_c, a.tc_se_ppm_per_c, "
     "a.nonlinearity_max_ppm_fs, a.asymmetry_ppm, a.asymmetry_se_ppm, a.tilt_mrad, a.tilt_se_mrad, "
     "a.turn_on_repeatability_dph, a.turn_on_repeatability_lower_dph, "
     "a.turn_on_repeatability_upper_dph, a.max_warmup_s, a.figures_json FROM acceptance_results "
     "AS a JOIN runs AS r ON r.id = a.run_id WHERE a.run_id = :id",
     Merge::replace_set},
    // Every power_cycles step's turn-on figures (station migration 15, fleet version 7).
    {"acceptance_turn_on_steps", Item::run,
     "run_uuid,serial,step_no,step_index,label,temp_c,ok,error,turn_ons,repeatability_dph,"
     "repeatability_lower_dph,repeatability_upper_dph,max_warmup_s",
     "run_uuid,serial,step_no",
     "SELECT r.uuid, t.serial, t.step_no, t.step_index, t.label, t.temp_c, t.ok, t.error, "
     "t.turn_ons, t.repeatability_dph, t.repeatability_lower_dph, t.repeatability_upper_dph, "
     "t.max_warmup_s FROM acceptance_turn_on_steps AS t JOIN runs AS r ON r.id = t.run_id WHERE "
     "t.run_id = :id",
     Merge::replace_set},
    {"events", Item::run, "run_uuid,local_id,t_s,wall_utc,severity,source,kind,message,data_json",
     "run_uuid,local_id",
     "SELECT r.uuid, e.id, e.t_s, e.wall_utc, e.severity, e.source, e.kind, e.message, "
     "e.data_json FROM events AS e JOIN runs AS r ON r.id = e.run_id WHERE e.run_id = :id AND "
     "e.id > :after ORDER BY e.id LIMIT :limit",
     Merge::append},
    {"samples", Item::run,
     "run_uuid,serial,t_s,net_pulses,interval_s,rate_dph,temp_c,temp2_c,air_c,setpoint_c,flags,"
     "recording",
     "run_uuid,serial,t_s",
     "SELECT r.uuid, s.serial, s.t_s, s.net_pulses, s.interval_s, s.rate_dph, s.temp_c, "
     "s.temp2_c, s.air_c, s.setpoint_c, s.flags, s.recording FROM samples AS s JOIN runs AS r "
     "ON r.id = s.run_id WHERE s.run_id = :id AND s.serial = :serial AND s.t_s > :after "
     "ORDER BY s.t_s LIMIT :limit",
     Merge::append},
    {"fits", Item::fit,
     "rev,uuid,station,local_id,serial,created_utc,runs_json,run_uuids_json,terms,ref_temp_c,"
     "coefficients_json,std_errors_json,n_bins,r2,residual_rms_dph,condition_number,"
     "std_before_dph,std_after_dph,std_ratio,warnings_json,std_errors_ols_json,error_model_json,"
     "part_number,verdict_json,adev_floor_dph,temp_min_c,temp_max_c,grad_min_c,grad_max_c,"
     "model_choice_json",
     "uuid",
     "SELECT " STATION_REV("fit", "f.id") ", f.uuid, " STATION_FIT_STATION(
         "f") ", f.id, f.serial, f.created_utc, f.runs_json, "
              "(SELECT json_group_array(r.uuid) FROM json_each(f.runs_json) AS j JOIN runs AS r ON "
              "r.id = "
              "j.value), f.terms, f.ref_temp_c, f.coefficients_json, f.std_errors_json, f.n_bins, "
              "f.r2, "
              "f.residual_rms_dph, f.condition_number, f.std_before_dph, f.std_after_dph, "
              "f.std_ratio, "
              "f.warnings_json, f.std_errors_ols_json, f.error_model_json, f.part_number, "
              "f.verdict_json, "
              "f.adev_floor_dph, f.temp_min_c, f.temp_max_c, f.grad_min_c, f.grad_max_c, "
              "f.model_choice_json FROM fits AS f WHERE f.id = :id",
     Merge::upsert},
    {"releases", Item::release,
     "rev,uuid,station,local_id,fit_uuid,serial,released_utc,released_by,note,override_reason,"
     "verdict_json",
     "uuid",
     "SELECT " STATION_REV("release", "l.id") ", l.uuid, " STATION_FIT_STATION(
         "f") ", l.id, f.uuid, l.serial, l.released_utc, "
              "l.released_by, l.note, l.override_reason, "
              "l.verdict_json FROM releases AS l JOIN fits AS f "
              "ON f.id = l.fit_id WHERE l.id = :id",
     Merge::upsert},
    {"verifications", Item::verification,
     "rev,uuid,station,local_id,fit_uuid,run_uuid,serial,created_utc,result_json,part_number,"
     "verdict_json",
     "uuid",
     "SELECT " STATION_REV("verification",
                           "v.id") ", v.uuid, r.station, v.id, f.uuid, r.uuid, v.serial, "
                                   "v.created_utc, v.result_json, "
                                   "v.part_number, v.verdict_json FROM verifications AS v JOIN "
                                   "fits AS f ON f.id = v.fit_id "
                                   "JOIN runs AS r ON r.id = v.run_id WHERE v.id = :id",
     Merge::upsert},
};

#undef STATION_FIT_STATION
#undef STATION_REV

}  // namespace

std::string_view item_name(Item i) {
  switch (i) {
    case Item::run:
      return "run";
    case Item::fit:
      return "fit";
    case Item::release:
      return "release";
    case Item::verification:
      return "verification";
  }
  return "?";
}

const std::vector<FleetTable>& fleet_tables() {
  return kTables;
}

const FleetTable& fleet_table(std::string_view name) {
  for (const auto& t : kTables)
    if (t.name == name) return t;
  throw std::out_of_range("no fleet table " + std::string(name));
}

std::vector<std::string_view> split_columns(std::string_view list) {
  std::vector<std::string_view> out;
  while (!list.empty()) {
    const auto comma = list.find(',');
    out.push_back(list.substr(0, comma));
    if (comma == std::string_view::npos) break;
    list.remove_prefix(comma + 1);
  }
  return out;
}

}  // namespace station::fleet
