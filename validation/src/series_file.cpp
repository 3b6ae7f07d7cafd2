#include "physval/validation/series_file.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <system_error>

#include "number_text.hpp"

namespace physval {

namespace {

constexpr std::string_view kMagic = "physval-series 1 ";
constexpr std::size_t kMaxNumber = 32;   // the longest %.12g text, with room

std::size_t body_columns(const RunRecord& r) { return std::min(r.bodies.size(), kMaxBodiesInSeries); }

}  // namespace

std::string series_header(const RunRecord& r) {
  std::string header = "t,energy,kinetic,potential,px,py,angular_momentum";
  const std::size_t nb = body_columns(r);
  for (std::size_t i = 0; i < nb; ++i) {
    header += ",x_";
    header += r.bodies[i].name;
    header += ",y_";
    header += r.bodies[i].name;
  }
  return header;
}

std::size_t series_values(const RunRecord& r, std::vector<double>& out) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const std::size_t nb = body_columns(r);
  const std::size_t columns = 7 + 2 * nb;
  const std::size_t rows = r.series.time.size();
  out.resize(rows * columns);
  double* o = out.data();
  for (std::size_t k = 0; k < rows; ++k) {
    const Totals t = k < r.series.totals.size() ? r.series.totals[k] : Totals{};
    o[0] = r.series.time[k];
    o[1] = t.energy();
    o[2] = t.kinetic;
    o[3] = t.potential;
    o[4] = t.momentum.x;
    o[5] = t.momentum.y;
    o[6] = t.angular_momentum;
    o += 7;
    const std::size_t have = k < r.series.states.size() ? std::min(nb, r.series.states[k].size()) : 0;
    if (have > 0) {
      const SampleState* st = r.series.states[k].data();
      for (std::size_t i = 0; i < have; ++i) {
        o[2 * i] = st[i].alive ? st[i].position.x : kNaN;
        o[2 * i + 1] = st[i].alive ? st[i].position.y : kNaN;
      }
    }
    std::fill(o + 2 * have, o + 2 * nb, kNaN);
    o += 2 * nb;
  }
  return columns;
}

std::size_t series_csv_capacity(std::size_t header_size, std::size_t rows, std::size_t columns) {
  return header_size + 1 + rows * columns * (kMaxNumber + 1);
}

char* write_series_csv(char* o, std::string_view header, const double* values, std::size_t rows, std::size_t columns) {
  std::memcpy(o, header.data(), header.size());
  o += header.size();
  *o++ = '\n';
  for (std::size_t k = 0; k < rows; ++k) {
    const double* row = values + k * columns;
    for (std::size_t c = 0; c < columns; ++c) {
      if (c > 0) *o++ = ',';
      const double v = row[c];
      if (std::isnan(v)) {
        std::memcpy(o, "nan", 3);
        o += 3;
      } else {
        o = to_chars_g12(o, o + kMaxNumber, v);
      }
    }
    *o++ = '\n';
  }
  return o;
}

void append_series_csv(std::string& out, std::string_view header, const double* values, std::size_t rows,
                       std::size_t columns) {
  std::unique_ptr<char[]> buffer(new char[series_csv_capacity(header.size(), rows, columns)]);   // not zeroed
  const char* end = write_series_csv(buffer.get(), header, values, rows, columns);
  out.append(buffer.get(), static_cast<std::size_t>(end - buffer.get()));
}

std::string series_binary_prefix(std::string_view header, std::size_t rows, std::size_t columns) {
  std::string p(kMagic);
  p += std::to_string(rows);
  p += ' ';
  p += std::to_string(columns);
  p += '\n';
  p += header;
  while ((p.size() + 1) % 8 != 0) p += ' ';
  p += '\n';
  return p;
}

void append_series_binary(std::string& out, std::string_view header, const double* values, std::size_t rows,
                          std::size_t columns) {
  out += series_binary_prefix(header, rows, columns);
  const std::size_t at = out.size();
  out.resize(at + rows * columns * sizeof(double));
  std::memcpy(out.data() + at, values, rows * columns * sizeof(double));
  if constexpr (std::endian::native == std::endian::big) {
    for (std::size_t k = at; k < out.size(); k += sizeof(double)) std::reverse(out.data() + k, out.data() + k + sizeof(double));
  }
}

std::optional<SeriesTable> read_series_binary(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  auto bad = [&](const std::string& why) {
    return std::runtime_error(file.string() + ": not a physval series file (" + why + ")");
  };
  std::string first, header;
  if (!std::getline(in, first) || first.compare(0, kMagic.size(), kMagic) != 0) throw bad("no \"physval-series 1\" line");
  std::size_t rows = 0, columns = 0;
  {
    const char* p = first.data() + kMagic.size();
    const char* end = first.data() + first.size();
    auto r1 = std::from_chars(p, end, rows);
    if (r1.ec != std::errc() || r1.ptr == end || *r1.ptr != ' ') throw bad("the row count");
    auto r2 = std::from_chars(r1.ptr + 1, end, columns);
    if (r2.ec != std::errc() || r2.ptr != end) throw bad("the column count");
  }
  if (!std::getline(in, header)) throw bad("no header line");
  while (!header.empty() && header.back() == ' ') header.pop_back();
  SeriesTable t;
  for (std::size_t from = 0;;) {
    const std::size_t comma = header.find(',', from);
    t.names.push_back(header.substr(from, comma == std::string::npos ? std::string::npos : comma - from));
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
  if (t.names.size() != columns) throw bad("the header names " + std::to_string(t.names.size()) + " columns, not " + std::to_string(columns));
  const auto data_at = static_cast<std::uintmax_t>(in.tellg());
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec || columns == 0 || rows > (size - std::min(size, data_at)) / sizeof(double) / columns ||
      size - data_at != static_cast<std::uintmax_t>(rows) * columns * sizeof(double)) {
    throw bad("its size is not its rows x columns doubles");
  }
  t.rows = rows;
  t.values.resize(rows * columns);
  if (!in.read(reinterpret_cast<char*>(t.values.data()), static_cast<std::streamsize>(t.values.size() * sizeof(double)))) {
    throw bad("truncated");
  }
  if constexpr (std::endian::native == std::endian::big) {
    auto* bytes = reinterpret_cast<char*>(t.values.data());
    for (std::size_t k = 0; k < t.values.size(); ++k) std::reverse(bytes + k * 8, bytes + k * 8 + 8);
  }
  return t;
}

std::size_t convert_series_to_csv(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  const fs::path root = dir / "series";
  std::size_t written = 0;
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return 0;
  std::vector<fs::path> files;
  for (const fs::directory_entry& scenario : fs::directory_iterator(root)) {
    if (!scenario.is_directory()) continue;
    for (const fs::directory_entry& f : fs::directory_iterator(scenario.path())) {
      if (f.is_regular_file() && f.path().extension() == ".bin") files.push_back(f.path());
    }
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    const std::optional<SeriesTable> t = read_series_binary(f);
    if (!t) throw std::runtime_error("cannot read " + f.string());
    std::string header;
    for (std::size_t c = 0; c < t->names.size(); ++c) {
      if (c > 0) header += ',';
      header += t->names[c];
    }
    std::string text;
    append_series_csv(text, header, t->values.data(), t->rows, t->names.size());
    fs::path csv = f;
    csv.replace_extension(".csv");
    std::string tmp_name = ".";   // appended, not "." + ...: GCC 12's -Wrestrict false positive
    tmp_name.append(csv.filename().string()).append(".tmp");
    const fs::path tmp = csv.parent_path() / tmp_name;
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out.write(text.data(), static_cast<std::streamsize>(text.size()));
      if (!out.flush()) throw std::runtime_error("cannot write " + tmp.string());
    }
    fs::rename(tmp, csv);
    ++written;
  }
  return written;
}

}  // namespace physval
