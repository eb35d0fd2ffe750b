// Records: a result struct's one field list (name, unit, description) from which come its
// JSON in a result, its exact codec (a job's result between processes, a cache entry), its
// CSV columns and, through the JSON, the Python module's dict. A struct becomes a record by
// declaring
//
//   static const base::Fields<Point>& fields();
//
// and defining it once beside its code:
//
//   const base::Fields<Point>& Point::fields() {
//     static const auto f = base::Fields<Point>()
//         .field("frequency_hz", &Point::frequency_hz, "Hz", "the frequency as run")
//         .field("spread", &Point::spread, "", "standard deviation of the periods' amplitudes", base::kNullable)
//         .derived("periods", [](const Point& p) { return p.periods(); }, "", "periods run");
//     return f;
//   }
//
// Then `base::to_json(point)` is its result JSON, `nlohmann::json(point)` and
// `j.get<Point>()` its exact codec, and `base::CsvTable<Point>` writes rows of it. The codec
// carries the members listed and nothing else: a record that crosses processes (a job's
// result) lists every member.
#pragma once

#include <cmath>
#include <concepts>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

namespace pdamp::base {

/// How a field is written (bits, combined with |).
enum FieldFlag : unsigned {
  /// In a result, a number that is not finite is null ("not known"); the codec keeps it.
  kNullable = 1u << 0,
  /// A vector with one value per output (a damper, a site): in a result an object keyed by
  /// the output names when they are known (JsonStyle::outputs), else an array.
  kPerOutput = 1u << 1,
  /// Left out of the result JSON: state a result does not show (a long sample series, a
  /// value only a CSV table or a view names). The codec carries it when it is a member.
  kHidden = 1u << 2,
  /// In a result, left out when it is empty (an optional without a value, a null).
  kOmitEmpty = 1u << 3,
};

/// Which form a record is written in.
struct JsonStyle {
  /// The codec: every member, numbers as they are (CBOR keeps every double and NaN), enums
  /// as numbers, no derived fields; read back by Fields::from_json of the same build.
  bool exact = false;
  /// The names of a kPerOutput field's values, in order (nullptr: written as an array).
  const std::vector<std::string>* outputs = nullptr;
};

template <class T>
class Fields;

/// A struct with a field list: `static const base::Fields<T>& fields();`.
template <class T>
concept Record = requires {
  { T::fields() } -> std::same_as<const Fields<T>&>;
};

namespace detail {

template <class T>
struct is_vector : std::false_type {};
template <class T, class A>
struct is_vector<std::vector<T, A>> : std::true_type {};
template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};

/// An enum's name in results: its to_string (found by argument-dependent lookup).
template <class E>
std::string enum_name(E value) {
  return std::string(to_string(value));
}

template <class V>
nlohmann::json value_json(const V& value, unsigned flags, const JsonStyle& style);

template <class V>
nlohmann::json vector_json(const std::vector<V>& values, unsigned flags, const JsonStyle& style) {
  if ((flags & kPerOutput) && style.outputs && !style.exact) {
    nlohmann::json out = nlohmann::json::object();
    for (std::size_t i = 0; i < values.size() && i < style.outputs->size(); ++i)
      out[(*style.outputs)[i]] = value_json(values[i], flags & ~kPerOutput, style);
    return out;
  }
  nlohmann::json out = nlohmann::json::array();
  for (const auto& v : values) out.push_back(value_json(v, flags & ~kPerOutput, style));
  return out;
}

template <class V>
nlohmann::json value_json(const V& value, unsigned flags, const JsonStyle& style) {
  if constexpr (Record<V>) {
    return V::fields().to_json(value, style);
  } else if constexpr (std::is_floating_point_v<V>) {
    if (!style.exact && (flags & kNullable) && !std::isfinite(value)) return nullptr;
    return value;
  } else if constexpr (std::is_enum_v<V>) {
    if (style.exact) return static_cast<std::underlying_type_t<V>>(value);
    return enum_name(value);
  } else if constexpr (is_vector<V>::value) {
    return vector_json(value, flags, style);
  } else if constexpr (is_optional<V>::value) {
    if (!value) return nullptr;
    return value_json(*value, flags, style);
  } else {
    return value;  // bool, integers, strings
  }
}

template <class V>
void value_from_json(const nlohmann::json& j, V& value) {
  if constexpr (Record<V>) {
    V::fields().from_json(j, value);
  } else if constexpr (std::is_floating_point_v<V>) {
    value = j.is_null() ? NAN : j.get<V>();
  } else if constexpr (std::is_enum_v<V>) {
    value = static_cast<V>(j.get<std::underlying_type_t<V>>());
  } else if constexpr (is_vector<V>::value) {
    value.clear();
    value.resize(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) value_from_json(j[i], value[i]);
  } else if constexpr (is_optional<V>::value) {
    if (j.is_null()) {
      value.reset();
    } else {
      value.emplace();
      value_from_json(j, *value);
    }
  } else {
    j.get_to(value);
  }
}

/// A CSV cell: numbers with 10 significant digits (`nan_text` where not finite), booleans
/// as 1 and 0, text as it is (CSV text in pdamp holds no commas: names are checked).
template <class V>
std::string csv_cell(const V& value, std::string_view nan_text) {
  if constexpr (std::is_floating_point_v<V>) {
    if (!std::isfinite(value) && nan_text != "nan") return std::string(nan_text);
    std::ostringstream out;
    out.imbue(std::locale::classic());
    out.precision(10);
    out << value;
    return out.str();
  } else if constexpr (std::is_same_v<V, bool>) {
    return value ? "1" : "0";
  } else if constexpr (std::is_enum_v<V>) {
    return enum_name(value);
  } else if constexpr (std::is_arithmetic_v<V>) {
    return std::to_string(value);
  } else {
    return std::string(value);
  }
}

}  // namespace detail

/// The field list of record T.
template <class T>
class Fields {
 public:
  /// One entry: a member, a value derived from the record, or a group of entries written as
  /// a nested object.
  struct Entry {
    std::string name, unit, description;
    unsigned flags = 0;
    std::function<nlohmann::json(const T&, const JsonStyle&)> write;
    std::function<void(const nlohmann::json&, T&)> read;  ///< empty: derived (results only)
    /// The CSV cells of the value: one, or one per output of a kPerOutput vector.
    std::function<std::vector<std::string>(const T&, std::string_view nan_text)> cells;
    std::shared_ptr<const Fields<T>> group;  ///< a nested object of the record's own fields
  };

  /// Member `member`, written as `name`; `unit` "" for none (the name carries SI units).
  template <class M>
  Fields& field(std::string name, M T::*member, std::string unit, std::string description, unsigned flags = 0) & {
    Entry e{std::move(name), std::move(unit), std::move(description), flags, {}, {}, {}, nullptr};
    e.write = [member, flags](const T& r, const JsonStyle& s) { return detail::value_json(r.*member, flags, s); };
    e.read = [member](const nlohmann::json& j, T& r) { detail::value_from_json(j, r.*member); };
    e.cells = [member](const T& r, std::string_view nan_text) { return cells_of(r.*member, nan_text); };
    entries_.push_back(std::move(e));
    return *this;
  }
  template <class M>
  Fields&& field(std::string name, M T::*member, std::string unit, std::string description, unsigned flags = 0) && {
    return std::move(field(std::move(name), member, std::move(unit), std::move(description), flags));
  }

  /// Member record `member` written in results with the entries of `shown` (a view of its
  /// own list); the codec keeps all of them.
  template <Record M>
  Fields& field(std::string name, M T::*member, const Fields<M>& shown, std::string description, unsigned flags = 0) & {
    Entry e{std::move(name), "", std::move(description), flags, {}, {}, {}, nullptr};
    e.write = [member, &shown](const T& r, const JsonStyle& s) {
      return s.exact ? detail::value_json(r.*member, 0, s) : shown.to_json(r.*member, s);
    };
    e.read = [member](const nlohmann::json& j, T& r) { detail::value_from_json(j, r.*member); };
    entries_.push_back(std::move(e));
    return *this;
  }
  template <Record M>
  Fields&& field(std::string name, M T::*member, const Fields<M>& shown, std::string description, unsigned flags = 0) && {
    return std::move(field(std::move(name), member, shown, std::move(description), flags));
  }

  /// A value computed from the record (results and CSV only; the codec carries what it is
  /// computed from).
  template <class Get>
  Fields& derived(std::string name, Get get, std::string unit, std::string description, unsigned flags = 0) & {
    Entry e{std::move(name), std::move(unit), std::move(description), flags, {}, {}, {}, nullptr};
    e.write = [get, flags](const T& r, const JsonStyle& s) { return detail::value_json(get(r), flags, s); };
    e.cells = [get](const T& r, std::string_view nan_text) { return cells_of(get(r), nan_text); };
    entries_.push_back(std::move(e));
    return *this;
  }
  template <class Get>
  Fields&& derived(std::string name, Get get, std::string unit, std::string description, unsigned flags = 0) && {
    return std::move(derived(std::move(name), std::move(get), std::move(unit), std::move(description), flags));
  }

  /// Entries of this record written as one nested object `name`.
  Fields& group(std::string name, std::string description, Fields<T> inner) & {
    Entry e{std::move(name), "", std::move(description), 0, {}, {}, {}, nullptr};
    e.group = std::make_shared<const Fields<T>>(std::move(inner));
    entries_.push_back(std::move(e));
    return *this;
  }
  Fields&& group(std::string name, std::string description, Fields<T> inner) && {
    return std::move(group(std::move(name), std::move(description), std::move(inner)));
  }

  /// The entries named, in that order: the same definitions written in a second place (a
  /// shorter summary), kHidden ones included. "key=entry" writes an entry under another
  /// key; "group/name" is an entry of a group. std::logic_error for a name that is no entry.
  Fields view(std::initializer_list<std::string_view> names) const {
    Fields out;
    for (const auto name : names) {
      const auto equals = name.find('=');
      const std::string_view path = equals == std::string_view::npos ? name : name.substr(equals + 1);
      const auto slash = path.find('/');
      out.entries_.push_back(slash == std::string_view::npos ? entry(path)
                                                             : group_of(path.substr(0, slash)).entry(path.substr(slash + 1)));
      if (equals != std::string_view::npos) out.entries_.back().name = std::string(name.substr(0, equals));
      out.entries_.back().flags &= ~kHidden;
    }
    return out;
  }

  /// The group entry `name`'s fields; std::logic_error when it is no group.
  const Fields& group_of(std::string_view name) const {
    const auto& e = entry(name);
    if (!e.group) throw std::logic_error("'" + std::string(name) + "' is no group");
    return *e.group;
  }

  const std::vector<Entry>& entries() const { return entries_; }
  const Entry& entry(std::string_view name) const {
    for (const auto& e : entries_)
      if (e.name == name) return e;
    throw std::logic_error("no field '" + std::string(name) + "'");
  }

  /// The record as a JSON object in `style`.
  nlohmann::json to_json(const T& record, const JsonStyle& style = {}) const {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& e : entries_) {
      if (e.group) {
        out[e.name] = e.group->to_json(record, style);
      } else if (written(e, style)) {
        nlohmann::json value = e.write(record, style);
        if (!style.exact && (e.flags & kOmitEmpty) && value.is_null()) continue;
        out[e.name] = std::move(value);
      }
    }
    return out;
  }

  /// The values of the record's entries in order (no groups): a table row.
  nlohmann::json to_array(const T& record, const JsonStyle& style = {}) const {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& e : entries_)
      if (!e.group && written(e, style)) out.push_back(e.write(record, style));
    return out;
  }

  /// The record from its codec form (to_json with JsonStyle::exact): every member entry;
  /// nlohmann::json's exception when one is missing or of another type.
  void from_json(const nlohmann::json& j, T& record) const {
    for (const auto& e : entries_) {
      if (e.group) e.group->from_json(j.at(e.name), record);
      else if (e.read) e.read(j.at(e.name), record);
    }
  }

  /// [{name, unit, description[, fields]}] of every entry: what each key means.
  nlohmann::json describe() const {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& e : entries_) {
      nlohmann::json d = {{"name", e.name}, {"unit", e.unit}, {"description", e.description}};
      if (e.group) d["fields"] = e.group->describe();
      out.push_back(std::move(d));
    }
    return out;
  }

 private:
  /// The codec writes the members; a result every entry but the hidden ones.
  static bool written(const Entry& e, const JsonStyle& style) {
    return style.exact ? static_cast<bool>(e.read) : !(e.flags & kHidden);
  }

  template <class V>
  static constexpr bool kCell = std::is_arithmetic_v<V> || std::is_enum_v<V> || std::is_convertible_v<V, std::string_view>;

  template <class V>
  static std::vector<std::string> cells_of(const V& value, std::string_view nan_text) {
    if constexpr (kCell<V>) {
      return {detail::csv_cell(value, nan_text)};
    } else if constexpr (detail::is_vector<V>::value) {
      if constexpr (kCell<typename V::value_type>) {
        std::vector<std::string> out;
        for (const auto& v : value) out.push_back(detail::csv_cell(v, nan_text));
        return out;
      }
    }
    throw std::logic_error("a nested record or optional is no CSV cell");
  }

  std::vector<Entry> entries_;
};

/// A record's result JSON; `outputs` names the values of its kPerOutput fields.
template <Record T>
nlohmann::json to_json(const T& record, const std::vector<std::string>* outputs = nullptr) {
  return T::fields().to_json(record, JsonStyle{false, outputs});
}
/// Records' result JSON as an array.
template <Record T>
nlohmann::json to_json(const std::vector<T>& records, const std::vector<std::string>* outputs = nullptr) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : records) out.push_back(to_json(r, outputs));
  return out;
}

/// Columns of a CSV table: a field of the row record by name ("group/name" inside a group,
/// its header "group_name"; "header=entry" under another header), or several kPerOutput
/// fields interleaved output by output.
class CsvColumn {
 public:
  CsvColumn(const char* field) : fields_{field} {}  // NOLINT: a name is a column
  CsvColumn(std::string field) : fields_{std::move(field)} {}  // NOLINT
  /// kPerOutput fields interleaved: a_<out1>, b_<out1>, a_<out2>, b_<out2>, ...
  CsvColumn(std::initializer_list<std::string> interleaved) : fields_(interleaved) {}

  /// The cell of a number that is not finite ("nan" by default; "" empty, "0", "-1").
  CsvColumn& nan_as(std::string text) {
    nan_text_ = std::move(text);
    return *this;
  }
  /// A kPerOutput field: the first output's value only.
  CsvColumn& first_output_only() {
    first_output_only_ = true;
    return *this;
  }
  /// A value of the first output that is not per output (a spread of the first site's
  /// amplitude): its header ends in _<first output>.
  CsvColumn& named_for_first_output() {
    named_for_first_output_ = true;
    return *this;
  }

 private:
  template <Record T>
  friend class CsvTable;
  std::vector<std::string> fields_;
  std::string nan_text_ = "nan";
  bool first_output_only_ = false;
  bool named_for_first_output_ = false;
};

/// A CSV table of records T: the header and each row from the same columns, so a column's
/// name and its values cannot part. A kPerOutput field gives a column per output,
/// `<field>_<output>` (`outputs`: the names as they appear in the header).
template <Record T>
class CsvTable {
 public:
  CsvTable(std::vector<CsvColumn> columns, std::vector<std::string> outputs = {})
      : columns_(std::move(columns)), outputs_(std::move(outputs)) {
    for (const auto& c : columns_) {
      std::vector<Column> parts;
      for (const auto& path : c.fields_) parts.push_back(column(path));
      parts_.push_back(std::move(parts));
    }
  }

  /// The header line, without its newline; `leading` column names (the caller's) first,
  /// `prefix` before each of the table's own (a record repeated along a row: "mode1_").
  std::string header(std::string_view leading = {}, const std::string& prefix = {}) const {
    std::vector<std::string> names;
    for (std::size_t k = 0; k < columns_.size(); ++k) {
      const auto& parts = parts_[k];
      if (!(parts.front().entry->flags & kPerOutput)) {
        names.push_back(prefix + parts.front().header +
                        (columns_[k].named_for_first_output_ && !outputs_.empty() ? "_" + outputs_.front() : ""));
        continue;
      }
      for (std::size_t d = 0; d < shown(k, outputs_.size()); ++d)
        for (const auto& part : parts) names.push_back(prefix + part.header + "_" + outputs_[d]);
    }
    return joined(leading, names);
  }

  /// The cells of `record`, comma-separated, without a newline; `leading` cells first.
  std::string row(const T& record, std::string_view leading = {}) const {
    std::vector<std::string> cells;
    for (std::size_t k = 0; k < columns_.size(); ++k) {
      std::vector<std::vector<std::string>> values;
      for (const auto& part : parts_[k]) values.push_back(part.entry->cells(record, columns_[k].nan_text_));
      for (std::size_t d = 0; d < shown(k, values.front().size()); ++d)
        for (const auto& v : values) cells.push_back(d < v.size() ? v[d] : std::string());
    }
    return joined(leading, cells);
  }

 private:
  struct Column {
    const typename Fields<T>::Entry* entry;
    std::string header;
  };
  static Column column(std::string_view name) {
    const auto equals = name.find('=');
    const std::string_view path = equals == std::string_view::npos ? name : name.substr(equals + 1);
    const auto slash = path.find('/');
    std::string header(equals == std::string_view::npos ? path : name.substr(0, equals));
    if (slash == std::string_view::npos) return {&T::fields().entry(path), header};
    if (equals == std::string_view::npos) header[slash] = '_';
    return {&T::fields().group_of(path.substr(0, slash)).entry(path.substr(slash + 1)), header};
  }
  std::size_t shown(std::size_t column, std::size_t count) const {
    return columns_[column].first_output_only_ ? std::min<std::size_t>(1, count) : count;
  }
  static std::string joined(std::string_view leading, const std::vector<std::string>& cells) {
    std::string out(leading);
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (!out.empty() || i > 0) out += ',';
      out += cells[i];
    }
    return out;
  }

  std::vector<CsvColumn> columns_;
  std::vector<std::string> outputs_;
  std::vector<std::vector<Column>> parts_;
};

}  // namespace pdamp::base

/// The codec of every record: nlohmann::json(record) and j.get<T>() (base::to_job_bytes).
template <class T>
struct nlohmann::adl_serializer<T, std::enable_if_t<pdamp::base::Record<T>>> {
  static void to_json(nlohmann::json& j, const T& record) {
    j = T::fields().to_json(record, pdamp::base::JsonStyle{true, nullptr});
  }
  static void from_json(const nlohmann::json& j, T& record) { T::fields().from_json(j, record); }
};
