// Issue 33, points 1-2: the ACUTROL's reply framing (bare CR LF lines, or the error/length
// header TM-8004 §2 gives non-GPIB links), its errors read as ACL reports them (status byte,
// error queue, the header's error code), and the command language's short forms, each over a
// real socket against the simulated unit.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "drivers/ascii/line_client.hpp"
#include "drivers/turntable/acutrol3000/acutrol3000_table.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "sim_devices/faces/acutrol_face.hpp"
#include "sim_devices/servers/line_server.hpp"
#include "sim_devices/turntable_sim.hpp"

namespace {

namespace dr = station::drivers;
namespace ac = station::drivers::acutrol3000;
namespace sim = station::sim;

const char* name_of(sim::AclFraming f) {
  return f == sim::AclFraming::bare ? "bare" : "header";
}

// A simulated ACUTROL on TCP and the station's driver on it.
struct AcutrolRig {
  explicit AcutrolRig(sim::AclFraming framing, ac::Framing driver = ac::Framing::automatic)
      : face(table, 50.0, framing), server(face) {
    server.start_tcp(0);
    acutrol = std::make_unique<dr::Acutrol3000Table>(
        "turntable", dr::ascii::parse_line_endpoint(server.endpoint()), 0.5, nullptr, driver);
  }
  sim::TurntableSim table{dr::turntable_map::generic_plc(1)};
  sim::AcutrolFace face;
  sim::LineServer server;
  std::unique_ptr<dr::Acutrol3000Table> acutrol;
};

// A plain client on the simulated unit's bare lines, as a person's script would talk to it.
struct Console {
  explicit Console(const sim::LineServer& server)
      : client("console", dr::ascii::parse_line_endpoint(server.endpoint()),
               dr::ascii::LineFraming{"\r\n", "\r\n", 4096}) {}
  std::string operator()(const std::string& line) {
    auto r = client.query(line);
    EXPECT_TRUE(r) << line << ": " << r.error().message;
    return r ? r.value() : std::string("<no reply>");
  }
  dr::ascii::LineClient client;
};

TEST(AcutrolFraming, EachFramingIsRecognizedAtConnect) {
  for (const auto framing : {sim::AclFraming::bare, sim::AclFraming::header}) {
    AcutrolRig rig(framing);
    ASSERT_TRUE(rig.acutrol->connect()) << name_of(framing);
    auto id = rig.acutrol->identify();
    ASSERT_TRUE(id) << id.error().message;
    EXPECT_NE(
        id.value().find(std::string("framing ") + name_of(framing) + ", recognized at connect"),
        std::string::npos)
        << id.value();
    EXPECT_NE(id.value().find("Acutrol3000"), std::string::npos) << id.value();
    ASSERT_TRUE(rig.acutrol->command({.mode = dr::TurntableMode::rate, .rate_dps = 10.0}));
    rig.table.step_to(30.0);
    auto s = rig.acutrol->read();
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_TRUE(s.value().at_rate) << name_of(framing);
  }
}

// Another interface lowers the rate limit behind the station's back: the unit refuses the demand
// the driver believed allowed. That is a refusal in both framings, never a success, and the
// error it queued does not haunt the next command.
TEST(AcutrolErrors, ARefusedCommandIsARefusalInBothFramings) {
  for (const auto framing : {sim::AclFraming::bare, sim::AclFraming::header}) {
    AcutrolRig rig(framing,
                   framing == sim::AclFraming::bare ? ac::Framing::bare : ac::Framing::header);
    ASSERT_TRUE(rig.acutrol->connect());
    dr::ascii::LineClient other("gui", dr::ascii::parse_line_endpoint(rig.server.endpoint()),
                                dr::ascii::LineFraming{"\r\n", "\r\n", 4096});
    // The GUI's command, its reply read in whichever framing the unit speaks.
    ASSERT_TRUE(other.query_detect(":Limit:Rate R,1,5", ac::kFrame));
    auto refused = rig.acutrol->command({.mode = dr::TurntableMode::rate, .rate_dps = 10.0});
    ASSERT_FALSE(refused) << name_of(framing) << ": a refused demand read as success";
    EXPECT_EQ(refused.error().kind, dr::ErrorKind::exception);
    const std::string& m = refused.error().message;
    EXPECT_NE(m.find("':Demand:Rate 1,10.00000' refused by the unit"), std::string::npos) << m;
    EXPECT_NE(m.find("PARAMETER OUT OF RANGE"), std::string::npos) << m;
    if (framing == sim::AclFraming::header) {
      EXPECT_NE(m.find("error code 3"), std::string::npos) << m;
    }
    EXPECT_DOUBLE_EQ(rig.table.rate_demand_dps(), 0.0);
    EXPECT_TRUE(rig.acutrol->command({.mode = dr::TurntableMode::rate, .rate_dps = 4.0}))
        << name_of(framing);
    EXPECT_DOUBLE_EQ(rig.table.rate_demand_dps(), 4.0);
    EXPECT_EQ(rig.face.status_byte(), 0u) << name_of(framing) << ": status left set";
  }
}

// A unit that refuses everything for a while (simrig's `table refuse`): reads and commands are
// refusals naming the request; once it ends, the link works at once.
TEST(AcutrolErrors, AnInjectedRefusalIsReadAsOne) {
  for (const auto framing : {sim::AclFraming::bare, sim::AclFraming::header}) {
    AcutrolRig rig(framing);
    ASSERT_TRUE(rig.acutrol->connect());
    rig.server.refuse_for(1e6, 6);
    auto r = rig.acutrol->read();
    ASSERT_FALSE(r) << name_of(framing);
    EXPECT_EQ(r.error().kind, dr::ErrorKind::exception);
    EXPECT_NE(r.error().message.find("':Read:Position? 1;Rate? 1' refused by the unit"),
              std::string::npos)
        << r.error().message;
    EXPECT_NE(r.error().message.find("ILLEGAL CMD"), std::string::npos) << r.error().message;
    auto stop = rig.acutrol->stop();
    ASSERT_FALSE(stop);
    EXPECT_NE(stop.error().message.find("':Mode:Off 1' refused"), std::string::npos);
    rig.server.clear_faults();
    EXPECT_TRUE(rig.acutrol->read());
    EXPECT_TRUE(rig.acutrol->stop());
  }
}

// The strings the public third-party client sends (acutrol3000.py), and the manual's own
// examples: accepted with no error queued; the manual's three bad examples set SYNTAX ERROR.
TEST(AcutrolShortForms, ThePublicClientsStringsAreAccepted) {
  AcutrolRig rig(sim::AclFraming::bare);
  Console ask(rig.server);
  EXPECT_EQ(ask("*idn?").rfind("Acutronic,Acutrol3000", 0), 0u);
  EXPECT_EQ(ask("*cls"), "");
  for (const char* c : {":int:close 1", ":mode 1,rate", ":dem:rate 1,0", ":lim:rate pos,1,500",
                        ":mode:off 1", ":Interlock:Reset"}) {
    EXPECT_EQ(ask(c), "") << c;
    EXPECT_EQ(ask("*stb?"), "0") << c << " queued an error";
  }
  EXPECT_EQ(ask(":lim:rate? pos,1"), "500.00000");
  const std::string pr = ask(":read:pos? 1;rate? 1");
  EXPECT_EQ(std::count(pr.begin(), pr.end(), ';'), 1) << pr;
  EXPECT_EQ(ask(":R:P? 1"), pr.substr(0, pr.find(';')));
  EXPECT_EQ(ask(":mode? 1"), "Off");
  EXPECT_EQ(ask("*stb?"), "0");
}

TEST(AcutrolShortForms, TheManualsExamplesParseAsItSays) {
  AcutrolRig rig(sim::AclFraming::bare);
  Console ask(rig.server);
  // [ACL] §2.1 p. 2, on axis 1 (the simulated table's one axis).
  for (const char* good : {":Demand:Position 1,10.5", ":Dem:Pos 1,10.50000", ":D:P 1,10.5"}) {
    EXPECT_EQ(ask(good), "") << good;
    EXPECT_EQ(ask("*STB?"), "0") << good;
    EXPECT_EQ(ask(":D:P? 1"), "10.50000") << good;
  }
  for (const char* bad : {":Demand:Posn 1,10.5", ":Dem;Pos 1,10.50000", ":D:P,1,10.5"}) {
    ask(":Demand:Position 1,0");
    EXPECT_EQ(ask(bad), "") << bad;
    EXPECT_EQ(ask("*STB?"), "192") << bad;  // EQ (bit 7) and MSS (bit 6), [ACL] p. 20
    EXPECT_NE(ask(":Status:MSG? QERROR").find("SYNTAX ERROR"), std::string::npos) << bad;
    EXPECT_EQ(ask("*STB?"), "0") << bad;  // the queue read empty
    EXPECT_EQ(ask(":D:P? 1"), "0.00000") << bad << " moved the demand";
  }
  // §2.2-2.3 p. 3-4: ';' stays in the subsystem, ';:' returns to the root, the first ':' is
  // optional, and a command not in the current subsystem is an error.
  EXPECT_EQ(ask("Demand:Pos 1,0.01;Rate 1,20"), "");
  EXPECT_EQ(ask(":DEM:POS? 1;RATE? 1;:M? 1"), "0.01000;20.00000;Off");
  EXPECT_EQ(ask(":INT:RES;CLOS 1"), "");
  EXPECT_EQ(ask(":I:C 1;:M:R 1"), "");
  EXPECT_EQ(ask(":M? 1"), "Rate");
  EXPECT_EQ(ask("*STB?"), "0");
  EXPECT_EQ(ask(":Demand:Position 1,1;Close 1"), "");
  const std::string why = ask(":Status:MSG? QERROR");
  EXPECT_NE(why.find("SYNTAX ERROR: Close 1 'Close' names no command here"), std::string::npos)
      << why;
  EXPECT_EQ(ask(":Interlock:Close? 1"), "");  // no query form: ILLEGAL CMD ([ACL] p. 32)
  EXPECT_NE(ask(":Stat:MSG? qerror").find("ILLEGAL CMD"), std::string::npos);
}

TEST(AcutrolShortForms, PrefixesResolveLevelByLevel) {
  const auto paths = [](std::string_view m) {
    std::string out;
    for (const auto& u : sim::parse_acl(m))
      out += (out.empty() ? "" : " ") + (u.error ? "error" : u.path + (u.query ? "?" : ""));
    return out;
  };
  EXPECT_EQ(paths(":int:close 1"), ":Interlock:Close");                 // Interface has no Close
  EXPECT_EQ(paths(":I:C 1;C 2"), ":Interlock:Close :Interlock:Close");  // [ACL] p. 131
  EXPECT_EQ(paths(":I:R"), ":Interlock:Reset");                         // p. 136
  EXPECT_EQ(paths(":L:R R,3,100.0;R R,2,10.0"), ":Limit:Rate :Limit:Rate");           // p. 145
  EXPECT_EQ(paths(":L:V P,2,110.0;:DEM:RATE 2,100.0"), ":Limit:Vtrip :Demand:Rate");  // p. 146
  EXPECT_EQ(paths(":READ:POS? 1;POS 2"), ":Read:Position? :Read:Position?");          // p. 168
  EXPECT_EQ(paths(":R:R? 2;P? 1"), ":Read:Rate? :Read:Position?");                    // p. 169
  EXPECT_EQ(paths(":M:O 2;O 3"), ":Mode:Off :Mode:Off");                              // p. 150
  EXPECT_EQ(paths(":STAT:ese 5,0"), ":Status:ESE");                                   // p. 176
  EXPECT_EQ(paths(":mode 1,rate"), ":Mode");                                          // p. 147
  EXPECT_EQ(paths("*stb?;*CLS"), "*STB? *CLS");
  EXPECT_EQ(paths(":Dem;Pos 3,10.5"), "error");  // p. 2's bad examples
  EXPECT_EQ(paths(":D:P,3,10.5"), "error");
  EXPECT_EQ(paths(":Demand:Posn 3,10.5"), "error");
}

// A device that answers every request with the same bytes, unframed by the server.
class Crafted final : public sim::LineDevice {
 public:
  explicit Crafted(std::string bytes) : bytes_(std::move(bytes)) {}
  std::string request_terminator() const override { return "\n"; }
  std::string reply_terminator() const override { return ""; }
  std::optional<std::string> handle(std::string_view) override { return bytes_; }
  std::string error_reply(std::string_view, int) override { return bytes_; }
  std::string encode(std::string reply) const override { return reply; }

 private:
  std::string bytes_;
};

std::string header(std::uint32_t code, std::uint32_t length) {
  std::string h;
  for (const std::uint32_t v : {code, length})
    for (int i = 0; i < 4; ++i) h += static_cast<char>((v >> (8 * i)) & 0xff);
  return h;
}

dr::Result<dr::ascii::Reply> frame_from(const std::string& bytes) {
  Crafted device(bytes);
  sim::LineServer server(device);
  server.start_tcp(0);
  dr::ascii::LineClient client("turntable", dr::ascii::parse_line_endpoint(server.endpoint()),
                               dr::ascii::LineFraming{"\r\n", "\n", 32768}, nullptr, 0.3);
  return client.query_frame("*IDN?", ac::kFrame);
}

TEST(AcutrolFraming, BadFramesAreProtocolErrorsNotHangs) {
  auto oversized = frame_from(header(0, 40000) + "abc");
  ASSERT_FALSE(oversized);
  EXPECT_EQ(oversized.error().kind, dr::ErrorKind::protocol);
  EXPECT_NE(oversized.error().message.find("frame length 40000 beyond the 32768"),
            std::string::npos)
      << oversized.error().message;
  for (const std::string& cut : {header(0, 20) + "short", header(0, 20).substr(0, 5)}) {
    auto truncated = frame_from(cut);
    ASSERT_FALSE(truncated);
    EXPECT_EQ(truncated.error().kind, dr::ErrorKind::protocol) << truncated.error().message;
    EXPECT_NE(truncated.error().message.find("cut short"), std::string::npos);
  }
  auto no_nul = frame_from(header(0, 3) + "abcX");
  ASSERT_FALSE(no_nul);
  EXPECT_NE(no_nul.error().message.find("not ended by a NUL"), std::string::npos);
  // The NUL after the string ([RT] p. 34), or counted in the length: both read the same.
  for (const std::string& ok :
       {header(0, 3) + std::string("abc\0", 4), header(0, 4) + std::string("abc\0", 4)}) {
    auto r = frame_from(ok);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r.value().payload, "abc");
  }
  // The driver on such a unit: its connect fails as a protocol error, in bounded time.
  Crafted device(header(0, 1u << 20));
  sim::LineServer server(device);
  server.start_tcp(0);
  dr::Acutrol3000Table acutrol("turntable", dr::ascii::parse_line_endpoint(server.endpoint()), 0.3);
  auto c = acutrol.connect();
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().kind, dr::ErrorKind::protocol) << c.error().message;
}

}  // namespace
