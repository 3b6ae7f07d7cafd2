#include "physval/validation/run_record_io.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <type_traits>
#include <memory>
#include <optional>
#include <string>

namespace physval {

namespace {

constexpr std::uint32_t kMagic = 0x70767231;   // "pvr1"
constexpr std::uint64_t kMaxCount = 1ull << 40;

// --- writing -----------------------------------------------------------------------

template <class Sink>
class Writer {
 public:
  explicit Writer(Sink& sink) : sink_(sink) {}
  void raw(const void* p, std::size_t n) { sink_.put(p, n); }
  // A long run of bytes (a series' block): straight from where it lies.
  void large(const void* p, std::size_t n) { sink_.put_large(p, n); }
  void u64(std::uint64_t v) { raw(&v, sizeof v); }
  void i64(std::int64_t v) { raw(&v, sizeof v); }
  void f64(double v) { raw(&v, sizeof v); }
  void b(bool v) {
    const std::uint8_t x = v ? 1 : 0;
    raw(&x, 1);
  }
  void str(const std::string& s) {
    u64(s.size());
    raw(s.data(), s.size());
  }
  void opt(const std::optional<double>& v) {
    b(v.has_value());
    if (v) f64(*v);
  }
  void state(const BodyState& s) {
    const double d[6] = {s.position.x, s.position.y, s.velocity.x, s.velocity.y, s.angle, s.angular_velocity};
    raw(d, sizeof d);
    b(s.alive);
  }

 private:
  Sink& sink_;
};

template <class Sink>
void write_record(Sink& sink, const RunRecord& r) {
  Writer<Sink> w(sink);
  w.u64(kMagic);
  w.str(r.scenario);
  w.str(r.engine);
  w.str(r.engine_version);
  w.str(r.precision);
  w.f64(r.dt);
  w.i64(r.steps);
  w.i64(r.steps_planned);
  w.i64(static_cast<std::int64_t>(r.status));
  w.str(r.reason);
  w.opt(r.diverged_at);
  w.f64(r.wall_seconds);
  w.f64(r.load_seconds);
  w.f64(r.step_cpu_seconds);
  w.u64(r.settings.size());
  for (const Setting& s : r.settings) {
    w.str(s.first);
    w.str(s.second);
  }
  w.u64(r.limits_hit.size());
  for (const std::string& s : r.limits_hit) w.str(s);
  w.u64(r.bodies.size());
  for (const BodyMeta& b : r.bodies) {
    w.str(b.name);
    w.f64(b.mass);
    w.f64(b.radius);
    w.b(b.is_static);
  }
  w.u64(r.contacts.size());
  for (const ContactRecord& c : r.contacts) {
    w.str(c.a);
    w.str(c.b);
    w.f64(c.time);
    w.i64(c.step);
  }
  w.u64(r.probes.size());
  for (const Probe& p : r.probes) {
    w.str(p.body);
    w.f64(p.max_y);
    w.f64(p.max_y_time);
    w.u64(p.apex_first.size());
    for (const auto& [threshold, time] : p.apex_first) {
      w.f64(threshold);
      w.f64(time);
    }
    w.f64(p.revolutions);
    w.f64(p.last_full_rev_time);
    w.i64(p.full_revolutions);
  }
  // The series as four blocks: the times, the totals, the rows' sizes and the rows' states
  // (the states' bytes as they lie in memory: read back into place, no decoding).
  const std::size_t ns = r.series.time.size();
  w.u64(ns);
  w.large(r.series.time.data(), ns * sizeof(double));
  if (r.series.totals.size() >= ns) {
    w.large(r.series.totals.data(), ns * sizeof(Totals));
  } else {
    for (std::size_t k = 0; k < ns; ++k) {
      const Totals t = k < r.series.totals.size() ? r.series.totals[k] : Totals{};
      w.raw(&t, sizeof t);
    }
  }
  const std::size_t rows = std::min(ns, r.series.states.size());
  {
    std::vector<std::uint64_t> sizes(ns, 0);
    for (std::size_t k = 0; k < rows; ++k) sizes[k] = r.series.states.row_start(k + 1) - r.series.states.row_start(k);
    w.large(sizes.data(), ns * sizeof(std::uint64_t));
  }
  w.large(r.series.states.data(), r.series.states.row_start(rows) * sizeof(SampleState));
  w.u64(r.final_states.size());
  for (const BodyState& s : r.final_states) w.state(s);
  const ContainmentRecord& c = r.containment;
  w.b(c.measured);
  w.f64(c.max_penetration);
  w.opt(c.max_penetration_time);
  w.str(c.max_penetration_what);
  w.b(c.escaped_bodies.has_value());
  w.i64(c.escaped_bodies.value_or(0));
  w.opt(c.first_escape_time);
  w.str(c.first_escape);
  w.u64(c.escaped_list.size());
  for (const std::uint32_t k : c.escaped_list) w.u64(k);
  w.u64(c.grazes.size());
  for (const ContainmentRecord::Graze& g : c.grazes) {
    w.u64(g.a);
    w.u64(g.b);
    w.f64(g.time);
    w.f64(g.step);
    w.f64(g.depth);
  }
  w.u64(c.grazes_dropped);
  w.opt(c.first_dropped_graze_time);
  w.u64(kMagic);
}

struct VectorSink {
  std::vector<std::uint8_t>& out;
  void put(const void* p, std::size_t n) {
    const auto* c = static_cast<const std::uint8_t*>(p);
    out.insert(out.end(), c, c + n);
  }
  void put_large(const void* p, std::size_t n) { put(p, n); }
};

struct FdSink {
  int fd;
  bool ok = true;
  // Not zeroed (make_unique_for_overwrite): a fresh 256 kB block is mapped on demand,
  // so a small record touches (and faults in) only the pages it fills.
  static constexpr std::size_t kSize = std::size_t{1} << 18;
  std::unique_ptr<std::uint8_t[]> buffer = std::make_unique_for_overwrite<std::uint8_t[]>(kSize);
  std::size_t used = 0;
  explicit FdSink(int f) : fd(f) {}
  void flush() {
    std::size_t done = 0;
    while (ok && done < used) {
      const ssize_t w = ::write(fd, buffer.get() + done, used - done);
      if (w < 0) {
        if (errno == EINTR) continue;
        ok = false;
        break;
      }
      done += static_cast<std::size_t>(w);
    }
    used = 0;
  }
  void put(const void* p, std::size_t n) {
    const auto* c = static_cast<const std::uint8_t*>(p);
    while (n > 0) {
      if (used == kSize) flush();
      const std::size_t k = std::min(n, kSize - used);
      std::memcpy(buffer.get() + used, c, k);
      used += k;
      c += k;
      n -= k;
    }
  }
  // Past the buffer: what it holds first, then the bytes straight from where they lie.
  void put_large(const void* p, std::size_t n) {
    if (n <= kSize - used) {
      put(p, n);
      return;
    }
    flush();
    const auto* c = static_cast<const std::uint8_t*>(p);
    while (ok && n > 0) {
      const ssize_t w = ::write(fd, c, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        ok = false;
        break;
      }
      c += w;
      n -= static_cast<std::size_t>(w);
    }
  }
};

// --- reading -----------------------------------------------------------------------

struct VectorSource {
  const std::vector<std::uint8_t>& in;
  std::size_t at = 0;
  void get(void* p, std::size_t n) {
    if (n > in.size() - at) throw std::runtime_error("run record: truncated");
    if (n == 0) return;   // p may be an empty vector's null data()
    std::memcpy(p, in.data() + at, n);
    at += n;
  }
  // The next n bytes when they are all at hand (then taken), else nullptr (nothing taken).
  const char* take(std::size_t n) {
    if (n > in.size() - at) return nullptr;
    const char* p = reinterpret_cast<const char*>(in.data() + at);
    at += n;
    return p;
  }
  void get_large(void* p, std::size_t n) { get(p, n); }
};

struct FdSource {
  int fd;
  std::optional<std::chrono::steady_clock::time_point> deadline;
  static constexpr std::size_t kSize = std::size_t{1} << 18;
  std::unique_ptr<std::uint8_t[]> buffer = std::make_unique_for_overwrite<std::uint8_t[]>(kSize);   // not zeroed
  std::size_t begin = 0, end = 0, total = 0;
  // Until the pipe has bytes (or the deadline passes: RecordTimeout).
  void wait_readable() {
    for (;;) {
      int wait_ms = -1;
      if (deadline) {
        const double left = std::chrono::duration<double>(*deadline - std::chrono::steady_clock::now()).count();
        if (left <= 0.0) throw RecordTimeout();
        wait_ms = static_cast<int>(std::ceil(std::min(left, 60.0) * 1000.0));
      }
      pollfd p{fd, POLLIN, 0};
      const int ready = ::poll(&p, 1, wait_ms);
      if (ready < 0 && errno == EINTR) continue;
      if (ready == 0) continue;   // re-checks the deadline
      return;
    }
  }
  // Up to n bytes into p, at least one.
  std::size_t read_some(void* p, std::size_t n) {
    for (;;) {
      wait_readable();
      const ssize_t got = ::read(fd, p, n);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) throw std::runtime_error("run record: the stream ended early");
      total += static_cast<std::size_t>(got);
      return static_cast<std::size_t>(got);
    }
  }
  void fill() {
    begin = 0;
    end = read_some(buffer.get(), kSize);
  }
  void get(void* p, std::size_t n) {
    auto* c = static_cast<std::uint8_t*>(p);
    while (n > 0) {
      if (begin == end) fill();
      const std::size_t k = std::min(n, end - begin);
      std::memcpy(c, buffer.get() + begin, k);
      begin += k;
      c += k;
      n -= k;
    }
  }
  // The next n bytes when the buffer holds them all (then taken), else nullptr (nothing taken).
  const char* take(std::size_t n) {
    if (n > end - begin) return nullptr;
    const char* p = reinterpret_cast<const char*>(buffer.get() + begin);
    begin += n;
    return p;
  }
  // A long run of bytes: what the buffer holds, then read from the pipe straight into p.
  void get_large(void* p, std::size_t n) {
    if (n == 0) return;   // p may be an empty vector's null data()
    auto* c = static_cast<std::uint8_t*>(p);
    const std::size_t k = std::min(n, end - begin);
    std::memcpy(c, buffer.get() + begin, k);
    begin += k;
    c += k;
    n -= k;
    while (n > 0) {
      const std::size_t got = read_some(c, n);
      c += got;
      n -= got;
    }
  }
};

template <class Source>
class Reader {
 public:
  explicit Reader(Source& source) : src_(source) {}
  std::uint64_t u64() {
    std::uint64_t v;
    src_.get(&v, sizeof v);
    return v;
  }
  std::uint64_t count() {
    const std::uint64_t n = u64();
    if (n > kMaxCount) throw std::runtime_error("run record: malformed (count " + std::to_string(n) + ")");
    return n;
  }
  std::int64_t i64() {
    std::int64_t v;
    src_.get(&v, sizeof v);
    return v;
  }
  double f64() {
    double v;
    src_.get(&v, sizeof v);
    return v;
  }
  bool b() {
    std::uint8_t x;
    src_.get(&x, 1);
    if (x > 1) throw std::runtime_error("run record: malformed (flag)");
    return x == 1;
  }
  std::string str() {
    const std::uint64_t n = count();
    // A string wholly in the source's buffer (names: nearly all) is made from it directly.
    if (const char* p = src_.take(static_cast<std::size_t>(n))) return std::string(p, static_cast<std::size_t>(n));
    std::string s;
    // Read in pieces: a corrupt length cannot allocate more than arrives.
    while (s.size() < n) {
      char buf[4096];
      const std::size_t k = std::min<std::uint64_t>(sizeof buf, n - s.size());
      src_.get(buf, k);
      s.append(buf, k);
    }
    return s;
  }
  std::optional<double> opt() {
    if (!b()) return std::nullopt;
    return f64();
  }
  BodyState state() {
    double d[6];
    src_.get(d, sizeof d);
    BodyState s;
    s.position = {d[0], d[1]};
    s.velocity = {d[2], d[3]};
    s.angle = d[4];
    s.angular_velocity = d[5];
    s.alive = b();
    return s;
  }
  void raw(void* p, std::size_t n) { src_.get(p, n); }
  void large(void* p, std::size_t n) { src_.get_large(p, n); }

 private:
  Source& src_;
};

// Reserves at most what a sane stream could fill, so a corrupt count fails on reading.
template <class T>
void reserve_some(std::vector<T>& v, std::uint64_t n) {
  v.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(n, 1u << 20)));
}

template <class Source>
RunRecord read_record(Source& source) {
  Reader<Source> rd(source);
  if (rd.u64() != kMagic) throw std::runtime_error("run record: not a physval run record");
  RunRecord r;
  r.scenario = rd.str();
  r.engine = rd.str();
  r.engine_version = rd.str();
  r.precision = rd.str();
  r.dt = rd.f64();
  r.steps = rd.i64();
  r.steps_planned = rd.i64();
  const std::int64_t status = rd.i64();
  if (status < 0 || status > static_cast<std::int64_t>(RunStatus::Error)) throw std::runtime_error("run record: malformed (status)");
  r.status = static_cast<RunStatus>(status);
  r.reason = rd.str();
  r.diverged_at = rd.opt();
  r.wall_seconds = rd.f64();
  r.load_seconds = rd.f64();
  r.step_cpu_seconds = rd.f64();
  for (std::uint64_t n = rd.count(), i = 0; i < n; ++i) {
    std::string k = rd.str();
    r.settings.emplace_back(std::move(k), rd.str());
  }
  for (std::uint64_t n = rd.count(), i = 0; i < n; ++i) r.limits_hit.push_back(rd.str());
  const std::uint64_t nb = rd.count();
  reserve_some(r.bodies, nb);
  for (std::uint64_t i = 0; i < nb; ++i) {
    BodyMeta b;
    b.name = rd.str();
    b.mass = rd.f64();
    b.radius = rd.f64();
    b.is_static = rd.b();
    r.bodies.push_back(std::move(b));
  }
  const std::uint64_t nc = rd.count();
  reserve_some(r.contacts, nc);
  for (std::uint64_t i = 0; i < nc; ++i) {
    ContactRecord c;
    c.a = rd.str();
    c.b = rd.str();
    c.time = rd.f64();
    c.step = rd.i64();
    r.contacts.push_back(std::move(c));
  }
  for (std::uint64_t n = rd.count(), i = 0; i < n; ++i) {
    Probe p;
    p.body = rd.str();
    p.max_y = rd.f64();
    p.max_y_time = rd.f64();
    for (std::uint64_t m = rd.count(), j = 0; j < m; ++j) {
      const double threshold = rd.f64();
      p.apex_first.emplace_back(threshold, rd.f64());
    }
    p.revolutions = rd.f64();
    p.last_full_rev_time = rd.f64();
    p.full_revolutions = static_cast<int>(rd.i64());
    r.probes.push_back(std::move(p));
  }
  // The series: its four blocks (write_record), each read straight into place. A corrupt
  // count cannot allocate much more than arrives: blocks are made in pieces of at most
  // kPiece elements as their bytes come, past the first.
  const std::uint64_t ns = rd.count();
  constexpr std::uint64_t kPiece = 1u << 20;
  auto read_block = [&](auto& v, std::uint64_t n) {
    using T = typename std::remove_reference_t<decltype(v)>::value_type;
    for (std::uint64_t done = 0; done < n;) {
      const auto m = static_cast<std::size_t>(std::min(kPiece, n - done));
      v.resize(static_cast<std::size_t>(done) + m);
      rd.large(v.data() + done, m * sizeof(T));
      done += m;
    }
  };
  read_block(r.series.time, ns);
  static_assert(std::is_trivially_copyable_v<Totals> && sizeof(Totals) == 5 * sizeof(double));
  read_block(r.series.totals, ns);
  std::vector<std::uint64_t> sizes64;
  read_block(sizes64, ns);
  std::uint64_t samples = 0;
  std::vector<std::size_t> sizes(sizes64.size());
  for (std::size_t k = 0; k < sizes64.size(); ++k) {
    if (sizes64[k] > kMaxCount || (samples += sizes64[k]) > kMaxCount) {
      throw std::runtime_error("run record: malformed (series of " + std::to_string(sizes64[k]) + " states a row)");
    }
    sizes[k] = static_cast<std::size_t>(sizes64[k]);
  }
  auto check_flags = [](const SampleState* p, std::size_t n) {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      if (bytes[i * sizeof(SampleState) + offsetof(SampleState, alive)] > 1) throw std::runtime_error("run record: malformed (flag)");
    }
  };
  if (samples <= 4 * kPiece) {
    SampleState* out = r.series.states.append_uninitialised(sizes);
    rd.large(out, static_cast<std::size_t>(samples) * sizeof(SampleState));
    check_flags(out, static_cast<std::size_t>(samples));
  } else {
    // Row by row (each in pieces): a corrupt size fails on reading, not allocating.
    for (const std::size_t n : sizes) {
      r.series.states.append_uninitialised({0});
      for (std::size_t done = 0; done < n;) {
        const std::size_t m = std::min<std::size_t>(kPiece, n - done);
        SampleState* out = r.series.states.extend_last_row_uninitialised(m);
        rd.large(out, m * sizeof(SampleState));
        check_flags(out, m);
        done += m;
      }
    }
  }
  const std::uint64_t nf = rd.count();
  reserve_some(r.final_states, nf);
  for (std::uint64_t i = 0; i < nf; ++i) r.final_states.push_back(rd.state());
  ContainmentRecord& c = r.containment;
  c.measured = rd.b();
  c.max_penetration = rd.f64();
  c.max_penetration_time = rd.opt();
  c.max_penetration_what = rd.str();
  const bool has_escaped = rd.b();
  const std::int64_t escaped = rd.i64();
  if (has_escaped) c.escaped_bodies = static_cast<int>(escaped);
  c.first_escape_time = rd.opt();
  c.first_escape = rd.str();
  const std::uint64_t ne = rd.count();
  reserve_some(c.escaped_list, ne);
  for (std::uint64_t k = 0; k < ne; ++k) c.escaped_list.push_back(static_cast<std::uint32_t>(rd.u64()));
  const std::uint64_t ng = rd.count();
  reserve_some(c.grazes, ng);
  for (std::uint64_t k = 0; k < ng; ++k) {
    ContainmentRecord::Graze g;
    g.a = static_cast<std::uint32_t>(rd.u64());
    g.b = static_cast<std::uint32_t>(rd.u64());
    g.time = rd.f64();
    g.step = rd.f64();
    g.depth = rd.f64();
    c.grazes.push_back(g);
  }
  c.grazes_dropped = rd.u64();
  c.first_dropped_graze_time = rd.opt();
  if (rd.u64() != kMagic) throw std::runtime_error("run record: malformed (no end mark)");
  return r;
}

}  // namespace

std::vector<std::uint8_t> encode_run_record(const RunRecord& r) {
  std::vector<std::uint8_t> bytes;
  VectorSink sink{bytes};
  write_record(sink, r);
  return bytes;
}

RunRecord decode_run_record(const std::vector<std::uint8_t>& bytes) {
  VectorSource source{bytes};
  RunRecord r = read_record(source);
  if (source.at != bytes.size()) throw std::runtime_error("run record: trailing bytes");
  return r;
}

bool write_run_record(int fd, const RunRecord& r) {
  FdSink sink(fd);
  write_record(sink, r);
  sink.flush();
  return sink.ok;
}

RunRecord read_run_record(int fd, std::optional<std::chrono::steady_clock::time_point> deadline, std::size_t& bytes_read) {
  FdSource source{fd, deadline};
  try {
    RunRecord r = read_record(source);
    bytes_read = source.total;
    return r;
  } catch (...) {
    bytes_read = source.total;
    throw;
  }
}

RunRecord read_run_record(int fd, std::optional<std::chrono::steady_clock::time_point> deadline, std::size_t& bytes_read,
                          double& after) {
  FdSource source{fd, deadline};
  try {
    RunRecord r = read_record(source);
    source.get(&after, sizeof after);
    bytes_read = source.total;
    // Nothing may follow: the writer sends its next record only when asked.
    if (source.begin != source.end) throw std::runtime_error("run record: trailing bytes");
    return r;
  } catch (...) {
    bytes_read = source.total;
    throw;
  }
}

}  // namespace physval
