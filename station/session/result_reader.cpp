// A SAX handler that builds the document like nlohmann's DOM parser, except the elements of the
// top-level "ticks" array, which go to a callback one by one.
#include "station/session/result_reader.hpp"

#include <fmt/format.h>

#include <istream>
#include <streambuf>
#include <vector>

#include "station/common/input_error.hpp"
#include "station/session/session_log.hpp"

namespace station {
namespace {

using nlohmann::json;

class TickStreamingSax final : public nlohmann::json_sax<json> {
 public:
  TickStreamingSax(std::string file, const std::function<void(json&&)>& on_tick)
      : file_(std::move(file)), on_tick_(on_tick) {}

  json take_root() { return std::move(root_); }

  bool null() override { return add(json(nullptr)); }
  bool boolean(bool v) override { return add(json(v)); }
  bool number_integer(number_integer_t v) override { return add(json(v)); }
  bool number_unsigned(number_unsigned_t v) override { return add(json(v)); }
  bool number_float(number_float_t v, const string_t&) override { return add(json(v)); }
  bool string(string_t& v) override { return add(json(std::move(v))); }
  bool binary(binary_t& v) override { return add(json::binary(std::move(v))); }
  bool start_object(std::size_t) override { return open(json::object()); }
  bool key(string_t& k) override {
    keys_.back() = std::move(k);
    return true;
  }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(json::array()); }
  bool end_array() override { return close(); }
  bool parse_error(std::size_t byte, const std::string&,
                   const nlohmann::detail::exception& e) override {
    throw InputError(fmt::format("{}: byte {}: not JSON ({})", file_, byte, e.what()));
  }

 private:
  bool open(json container) {
    open_.push_back(std::move(container));
    keys_.emplace_back();
    return true;
  }
  bool close() {
    json done = std::move(open_.back());
    open_.pop_back();
    keys_.pop_back();
    return add(std::move(done));
  }
  bool in_ticks() const {
    return open_.size() == 2 && open_[0].is_object() && keys_[0] == "ticks" && open_[1].is_array();
  }
  bool add(json v) {
    if (open_.empty()) {
      root_ = std::move(v);
    } else if (in_ticks()) {
      on_tick_(std::move(v));
    } else if (open_.back().is_array()) {
      open_.back().push_back(std::move(v));
    } else {
      open_.back()[keys_.back()] = std::move(v);
    }
    return true;
  }

  std::string file_;
  const std::function<void(json&&)>& on_tick_;
  std::vector<json> open_;         // containers being built, outermost first
  std::vector<std::string> keys_;  // per open container: the key its next value goes to
  json root_;
};

/// The file's lines, each with a newline, as a stream the parser reads: a line in memory at a time
/// (the text the parser sees, and so a "byte N" it names, is that of read_session_log's lines).
class LineStreamBuf final : public std::streambuf {
 public:
  explicit LineStreamBuf(LogLineReader& reader) : reader_(reader) {}
  const std::string& file() const { return reader_.file(); }

 protected:
  int_type underflow() override {
    std::string_view line;
    int line_no = 0;
    if (!reader_.next(line, line_no)) return traits_type::eof();
    line_.assign(line);
    line_.push_back('\n');
    setg(line_.data(), line_.data(), line_.data() + line_.size());
    return traits_type::to_int_type(line_.front());
  }

 private:
  LogLineReader& reader_;
  std::string line_;
};

}  // namespace

json read_result_file(const std::string& path, const std::function<void(json&&)>& on_tick) {
  LogLineReader reader(path);
  return read_result_file(reader, on_tick);
}

json read_result_file(LogLineReader& reader, const std::function<void(json&&)>& on_tick) {
  LineStreamBuf text(reader);
  std::istream in(&text);
  const std::string file = text.file();
  TickStreamingSax sax(file, on_tick);
  json::sax_parse(in, &sax);
  json root = sax.take_root();
  if (!root.is_object()) throw InputError(fmt::format("{}: not a JSON object", file));
  // An array's elements went to on_tick and left it empty; anything else was kept (fuzz finding).
  if (const auto t = root.find("ticks"); t != root.end() && !(t->is_array() && t->empty()))
    throw InputError(fmt::format("{}: key 'ticks': not an array", file));
  return root;
}

}  // namespace station
