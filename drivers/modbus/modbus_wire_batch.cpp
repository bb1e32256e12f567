// LibmodbusWire::read_batch: a batch of reads with every request on the wire before the first
// reply (modbus_wire.hpp says what fails how); the rest of the link is modbus_wire.cpp.
#include <algorithm>
#include <cerrno>

#include "drivers/common/exchange_deadline.hpp"
#include "drivers/modbus/modbus_adu.hpp"
#include "drivers/modbus/modbus_wire.hpp"

namespace station::drivers::modbus {

int LibmodbusWire::read_batch(std::span<const ReadRequest> requests) {
  if (framing() != Framing::tcp || requests.size() < 2 || gap_ > SteadyClock::duration::zero())
    return ModbusWire::read_batch(requests);
  if (!ctx_) {
    errno = ENOTCONN;
    return 0;
  }
  const auto deadline = ExchangeDeadline::bound(SteadyClock::now() + timeout_);
  if (begin(deadline) == -1) return 0;
  // Each request framed as read() frames it, with the next transaction id; sent in one send.
  std::vector<std::vector<std::uint8_t>> frames;
  std::vector<std::uint8_t> bytes;
  for (const auto& r : requests) {
    tid_ = static_cast<std::uint16_t>(tid_ + 1);
    frames.push_back(request_frame(
        Framing::tcp, tid_, read_request_adu(r.unit, static_cast<int>(r.fc), r.addr, r.count)));
    bytes.insert(bytes.end(), frames.back().begin(), frames.back().end());
  }
  if (send_frame(bytes, deadline) == -1) return ended(0);
  return ended(collect_batch(requests, frames, deadline));
}

int LibmodbusWire::collect_batch(std::span<const ReadRequest> requests,
                                 const std::vector<std::vector<std::uint8_t>>& frames,
                                 SteadyClock::time_point deadline) {
  const std::uint16_t first = transaction_id(frames.front());
  std::vector<std::vector<std::uint8_t>> replies(frames.size());
  std::size_t done = 0;
  // The requests from `from` whose replies have not come (but `begun`'s, whose rest is late_)
  // are given up: their replies, if they come, are dropped by id.
  const auto give_up = [&](std::size_t from, const std::vector<std::uint8_t>* begun) {
    for (std::size_t i = from; i < frames.size(); ++i) {
      const auto tid = transaction_id(frames[i]);
      const bool is_begun = begun != nullptr && begun->size() >= 2 && transaction_id(*begun) == tid;
      if (replies[i].empty() && !is_begun) abandon(tid);
    }
  };
  while (done < frames.size()) {
    if (!replies[done].empty()) {  // judged in request order: the first failure is the error
      if (const int err = check_reply(Framing::tcp, frames[done], replies[done]); err != 0) {
        give_up(done + 1, nullptr);
        errno = err;
        return static_cast<int>(done);
      }
      reply_words(Framing::tcp, replies[done], requests[done].count, requests[done].dest);
      ++done;
      continue;
    }
    std::vector<std::uint8_t> frame;
    if (receive_batch_frame(frame, deadline) == -1) {
      const int err = errno;
      give_up(done, &frame);
      if (err == ETIMEDOUT && !frame.empty()) late_ = frame;  // its rest is dropped as it comes
      errno = err == ETIMEDOUT && !frame.empty() ? ETIME : err;
      return static_cast<int>(done);
    }
    // A server may answer a batch in any order: each reply goes to the request of its id.
    const auto at = static_cast<std::uint16_t>(transaction_id(frame) - first);
    if (at < frames.size() && replies[at].empty()) {
      replies[at] = std::move(frame);
      continue;
    }
    if (const auto late = std::find(late_ids_.begin(), late_ids_.end(), transaction_id(frame));
        late != late_ids_.end()) {
      late_ids_.erase(late);  // an earlier exchange's late reply
      continue;
    }
    // It answers no request of the batch: what read() says of such a reply to the one awaited.
    give_up(done, nullptr);
    const int err = check_reply(Framing::tcp, frames[done], frame);
    errno = err != 0 ? err : EMBBADDATA;
    return static_cast<int>(done);
  }
  return static_cast<int>(done);
}

}  // namespace station::drivers::modbus
