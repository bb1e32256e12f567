// The ACL command tree, transcribed from [ACL] TM-8004-C: §3 (common commands, p. 14-21), §4
// (the subsystems, p. 28-197; page of each section) and Tables 5-7 (p. 23-24: the Act2000
// commands kept, the queries added to them, the new commands). Names as the COMMAND/QUERY lines
// spell them (`:Limit:Vtrip`, `:Read:Svector`, `:Demand:Ivariable`).
#include "sim_devices/sources/acutrol_sources.hpp"

namespace station::sim::sources::acutrol {
namespace {

constexpr unsigned C = kCommand, Q = kQuery, CQ = kCommand | kQuery,
                   RQ = kQuery | kQueryWithoutMark;  // the Read queries of p. 168-169

constexpr AclNode kFilter[] = {{"Alternate", 58, CQ, false, {}}, {"Select", 58, CQ, false, {}}};
constexpr AclNode kLut[] = {{"Fourier", 66, C, false, {}},  {"List", 66, Q, false, {}},
                            {"Mode", 66, CQ, false, {}},    {"Preset", 66, CQ, false, {}},
                            {"Restore", 66, CQ, false, {}}, {"Save", 66, C, false, {}},
                            {"Series", 66, CQ, false, {}}};
constexpr AclNode kOptical[] = {{"Home", 81, C, false, {}}};
constexpr AclNode kRealTime[] = {{"BlockRecord", 88, CQ, false, {}},
                                 {"Monitor", 88, CQ, false, {}},
                                 {"Setup", 88, CQ, false, {}},
                                 {"Tracker", 88, CQ, false, {}},
                                 {"Translator", 88, CQ, false, {}}};
constexpr AclNode kRestore[] = {{"Group", 98, C, false, {}}};
constexpr AclNode kSave[] = {{"Group", 99, C, false, {}}, {"FileVersion", 99, CQ, false, {}}};
constexpr AclNode kConfSystem[] = {{"Restore", 104, CQ, false, {}}, {"Save", 105, C, false, {}}};
constexpr AclNode kConfigure[] = {{"AIM", 41, CQ, false, {}},
                                  {"Analog", 42, CQ, true, {}},
                                  {"Axis", 44, CQ, false, {}},
                                  {"Conditioner", 45, CQ, false, {}},
                                  {"Correlation", 46, CQ, false, {}},
                                  {"DemandSum", 48, CQ, false, {}},
                                  {"DigitalIO", 50, CQ, false, {}},
                                  {"Discrete", 52, CQ, true, {}},
                                  {"Event", 54, CQ, false, {}},
                                  {"FbkChannel", 56, CQ, false, {}},
                                  {"Filter", 58, CQ, false, kFilter},
                                  {"GPIO", 63, CQ, false, {}},
                                  {"LUT", 66, CQ, false, kLut},
                                  {"Model", 75, CQ, false, {}},
                                  {"MotionStates", 77, CQ, false, {}},
                                  {"Motor", 78, CQ, false, {}},
                                  {"Optical", 80, CQ, false, kOptical},
                                  {"Oscillator", 82, CQ, false, {}},
                                  {"Ovariable", 0, CQ, true, {}},
                                  {"Plant", 83, CQ, false, {}},
                                  {"Ratiometric", 85, CQ, false, {}},
                                  {"RealTime", 88, CQ, false, kRealTime},
                                  {"Restore", 97, CQ, false, kRestore},
                                  {"Save", 99, CQ, false, kSave},
                                  {"Scaling", 101, CQ, false, {}},
                                  {"Summer", 102, CQ, false, {}},
                                  {"System", 104, 0, false, kConfSystem},
                                  {"Variable", 106, CQ, false, {}},
                                  {"Window", 0, CQ, true, {}}};
constexpr AclNode kAcquire[] = {{"Activate", 29, C, false, {}}, {"Channel", 30, CQ, false, {}},
                                {"Free", 32, CQ, false, {}},    {"Read", 33, Q, false, {}},
                                {"Sample", 34, CQ, false, {}},  {"Save", 36, C, false, {}},
                                {"Status", 37, Q, false, {}},   {"Trigger", 38, CQ, false, {}}};
constexpr AclNode kDemand[] = {
    {"Acceleration", 108, CQ, true, {}}, {"DeltaPosition", 109, CQ, false, {}},
    {"Ivariable", 110, CQ, false, {}},   {"Jerk", 0, CQ, false, {}},
    {"Oscillator", 111, CQ, true, {}},   {"Position", 112, CQ, true, {}},
    {"Rate", 113, CQ, true, {}},         {"ShortVector", 114, CQ, true, {}},
    {"Vector", 115, CQ, true, {}},       {"WorldCoords", 116, CQ, false, {}}};
constexpr AclNode kIeee488[] = {{"Local", 119, C, false, {}}};
constexpr AclNode kScramNet[] = {
    {"CSR", 122, CQ, false, {}}, {"Mode", 123, CQ, false, {}}, {"Reset", 124, C, false, {}}};
constexpr AclNode kVmic[] = {{"CSR", 126, CQ, false, {}}, {"Reset", 127, C, false, {}}};
constexpr AclNode kReflective[] = {{"Setup", 128, CQ, false, {}}};
constexpr AclNode kInterface[] = {
    {"IEEE488", 118, CQ, false, kIeee488}, {"Parallel", 120, CQ, false, {}},
    {"RS232", 121, CQ, false, {}},         {"ScramNet", 122, 0, false, kScramNet},
    {"VMIC", 125, CQ, false, kVmic},       {"ReflectiveMem", 128, 0, false, kReflective}};
constexpr AclNode kInterlock[] = {
    {"Close", 131, C, true, {}},     {"Configure", 132, CQ, false, {}},
    {"Control", 133, CQ, false, {}}, {"Logic", 134, CQ, false, {}},
    {"Open", 135, C, true, {}},      {"Reset", 136, C, true, {}}};
constexpr AclNode kGlobal[] = {{"Method", 142, CQ, false, {}}};
constexpr AclNode kLimit[] = {
    {"Absolute", 138, CQ, false, {}},    {"Acceleration", 139, CQ, true, {}},
    {"Bemf", 140, CQ, false, {}},        {"Global", 141, CQ, false, kGlobal},
    {"HighPosition", 143, CQ, true, {}}, {"LowPosition", 144, CQ, true, {}},
    {"Rate", 145, CQ, true, {}},         {"Vtrip", 146, CQ, true, {}}};
constexpr AclNode kMode[] = {{"Arate", 148, C, true, {}}, {"Home", 149, C, false, {}},
                             {"Off", 150, C, false, {}},  {"Position", 151, C, true, {}},
                             {"Rate", 152, C, false, {}}, {"Synthesis", 153, C, true, {}},
                             {"Track", 154, C, true, {}}};
constexpr AclNode kPlayback[] = {
    {"Activate", 156, CQ, false, {}}, {"Configure", 157, CQ, false, {}},
    {"Data", 158, CQ, false, {}},     {"List", 159, Q, false, {}},
    {"Restore", 160, CQ, false, {}},  {"Save", 161, CQ, false, {}},
    {"Trigger", 162, CQ, false, {}}};
constexpr AclNode kQueryNodes[] = {{"Error", 163, Q, false, {}},
                                   {"System", 163, Q, false, {}},
                                   {"TotalVariables", 163, Q, false, {}}};
constexpr AclNode kRead[] = {{"Acceleration", 165, Q, true, {}}, {"Fdelay", 0, Q, true, {}},
                             {"Logdata", 166, Q, false, {}},     {"Variable", 167, Q, false, {}},
                             {"Ovariable", 0, Q, true, {}},      {"Position", 168, RQ, true, {}},
                             {"Rate", 169, RQ, true, {}},        {"Svector", 170, Q, true, {}},
                             {"TimeClock", 0, Q, true, {}},      {"Vector", 171, Q, true, {}},
                             {"WorldCoords", 172, Q, false, {}}};
constexpr AclNode kStatus[] = {
    {"CSR", 175, Q, false, {}},  {"ESE", 176, CQ, false, {}},      {"ESR", 177, Q, false, {}},
    {"MSG", 178, Q, false, {}},  {"MSGCLR", 179, C, false, {}},    {"STB", 180, Q, false, {}},
    {"TFR", 181, CQ, false, {}}, {"Accumulator", 0, CQ, true, {}}, {"ECP", 183, CQ, true, {}},
    {"MIS", 185, CQ, true, {}},  {"Supervisor", 189, CQ, true, {}}};
constexpr AclNode kSystem[] = {{"Security", 193, CQ, false, {}}};
constexpr AclNode kMacro[] = {{"Close", 197, C, false, {}},  {"Execute", 197, C, false, {}},
                              {"Load", 197, C, false, {}},   {"Open", 197, C, false, {}},
                              {"Remove", 197, C, false, {}}, {"Stop", 197, C, false, {}},
                              {"Upload", 197, C, false, {}}};
constexpr AclNode kUtility[] = {{"Accumulator", 0, CQ, true, {}},
                                {"Beep", 0, C, true, {}},
                                {"Format", 195, CQ, true, {}},
                                {"Lockout", 196, CQ, true, {}},
                                {"Macro", 197, Q, false, kMacro},
                                {"Prompt", 0, C, true, {}},
                                {"RemoteLockout", 196, CQ, false, {}},
                                {"SRQ", 0, CQ, true, {}},
                                {"Touch", 0, C, true, {}}};

constexpr AclNode kRoot[] = {
    {"Acquire", 28, 0, false, kAcquire},     {"Configure", 40, 0, true, kConfigure},
    {"Demand", 107, 0, true, kDemand},       {"Interface", 117, 0, false, kInterface},
    {"Interlock", 130, Q, true, kInterlock},  // :Interlock? added to the Act2000's (p. 23)
    {"Limit", 137, CQ, true, kLimit},        {"Mode", 147, CQ, true, kMode},
    {"Playback", 155, 0, false, kPlayback},  {"Query", 163, 0, false, kQueryNodes},
    {"Read", 164, 0, true, kRead},           {"Status", 173, 0, true, kStatus},
    {"System", 192, 0, false, kSystem},      {"Utility", 194, 0, true, kUtility}};

constexpr AclNode kCommon[] = {
    {"*CLS", 14, C, false, {}},  {"*ESE", 14, CQ, false, {}}, {"*ESR", 14, Q, false, {}},
    {"*IDN", 15, Q, false, {}},  {"*IST", 15, Q, false, {}},  {"*OPC", 16, CQ, false, {}},
    {"*PRE", 16, CQ, false, {}}, {"*RST", 17, C, false, {}},  {"*SRE", 18, CQ, false, {}},
    {"*STB", 19, Q, false, {}},  {"*TRG", 20, C, false, {}},  {"*TST", 20, Q, false, {}},
    {"*WAI", 21, C, false, {}}};

}  // namespace

std::span<const AclNode> root() {
  return kRoot;
}

std::span<const AclNode> common() {
  return kCommon;
}

std::string_view error_text(std::uint32_t code) {
  for (const AclError& e : {kSyntaxError, kIllegalCommand, kParameterOutOfRange})
    if (e.code == code) return e.text;
  return {};
}

}  // namespace station::sim::sources::acutrol
