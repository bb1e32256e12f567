// What one replayed device answers from: the recorded exchanges in order, given whole (tests, the
// CAN-log replay) or pulled from the session's log as the daemon asks (station replay DIR: the log
// is read, answered and forgotten, a few lines ahead at most).
#pragma once

#include <cstddef>
#include <deque>
#include <functional>
#include <utility>
#include <vector>

namespace station {

template <typename T>
class ReplayFeed {
 public:
  /// The next item from the log; false at its end.
  using Pull = std::function<bool(T&)>;

  /// `items` first, then what `pull` gives; with `keep`, what was taken is kept for consumed().
  explicit ReplayFeed(std::vector<T> items = {}, Pull pull = {}, bool keep = true)
      : ahead_(std::make_move_iterator(items.begin()), std::make_move_iterator(items.end())),
        pull_(std::move(pull)),
        keep_(keep) {}

  /// The k-th item not taken yet (reading ahead as needed); nullptr past the end. Valid until it
  /// is taken.
  const T* peek(std::size_t k = 0) {
    while (ahead_.size() <= k) {
      T item;
      if (!pull_ || !pull_(item)) return nullptr;
      ahead_.push_back(std::move(item));
    }
    return &ahead_[k];
  }
  /// Takes the next item (peek() must have given one); valid until the next take.
  const T& take() {
    last_ = std::move(ahead_.front());
    ahead_.pop_front();
    ++taken_;
    if (keep_) consumed_.push_back(last_);
    return last_;
  }
  /// Items taken so far.
  std::size_t taken() const { return taken_; }
  /// The item taken last.
  const T& last() const { return last_; }
  /// Items not taken yet (reads the rest of the log: tests).
  std::size_t remaining() {
    while (peek(ahead_.size()) != nullptr) {
    }
    return ahead_.size();
  }
  /// Items read from the log and not taken yet.
  std::size_t read_ahead() const { return ahead_.size(); }
  /// The items taken so far, in order (kept only with `keep`).
  const std::vector<T>& consumed() const { return consumed_; }

 private:
  std::deque<T> ahead_;
  Pull pull_;
  bool keep_;
  std::size_t taken_ = 0;
  T last_{};
  std::vector<T> consumed_;
};

}  // namespace station
