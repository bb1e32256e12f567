// Modbus TCP read transactions per second on loopback against ChamberSim (one register per
// transaction, and one full ModbusChamber::read() of 7 points: 4 block reads on generic_plc).
#include <benchmark/benchmark.h>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace {

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;

void BM_ModbusTcpReadRegister(benchmark::State& state) {
  auto map = cm::generic_plc();
  station::sim::ChamberSim sim(map);
  station::sim::ModbusServer server(sim);
  server.start_tcp();
  mb::ModbusClient client("bench", mb::parse_endpoint(server.endpoint()), 1.0);
  if (!client.connect()) {
    state.SkipWithError("connect failed");
    return;
  }
  const auto& air = map.at(cm::kAir);
  for (auto _ : state) {
    auto v = client.read(air);
    if (!v) {
      state.SkipWithError(v.error().message.c_str());
      break;
    }
    benchmark::DoNotOptimize(v.value());
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["transactions_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ModbusTcpReadRegister)->UseRealTime();

void BM_ModbusChamberRead(benchmark::State& state) {
  auto map = cm::generic_plc();
  station::sim::ChamberSim sim(map);
  station::sim::ModbusServer server(sim);
  server.start_tcp();
  station::drivers::ModbusChamber chamber("bench", mb::parse_endpoint(server.endpoint()), map);
  for (auto _ : state) {
    auto s = chamber.read();
    if (!s) {
      state.SkipWithError(s.error().message.c_str());
      break;
    }
    benchmark::DoNotOptimize(s.value().air_c);
  }
  state.counters["reads_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ModbusChamberRead)->UseRealTime();

}  // namespace
