// Totals over the faces of a per-face report whose fields are declared once (a static
// fields(self, visit), see qsmesh/parallel/record.hpp), by the names given there: the summary and
// --stats read them by name, so a field added to the report is summed and written without an
// edit here.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "json.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/types.hpp"
#include "qsmesh/parallel/record.hpp"

namespace qsmesh::cli {

/// The sum of one field over the faces.
struct FieldTotal {
  std::string name;
  std::vector<std::int64_t> values;  ///< one, or one per element of an array field
  bool array = false;
};

/// Sums of a report's countable fields, in the order of its fields(): a bool counts the faces
/// where it holds, an integer or an array of integers adds up (element by element); text and
/// real numbers are per face and left out. Nested reports add their fields in place.
class ReportTotals {
 public:
  /// The totals of `reports` (their fields listed, at zero, when there are none).
  template <class R>
  [[nodiscard]] static ReportTotals sum(std::span<const R> reports) {
    ReportTotals t;
    t.add(R{});
    for (const R& r : reports) t.add(r);
    return t;
  }

  /// The total of field `name` (element k of an array field). Throws qsmesh::Error for a name the
  /// report does not have.
  [[nodiscard]] std::int64_t operator()(std::string_view name, std::size_t k = 0) const {
    for (const FieldTotal& f : fields_)
      if (f.name == name) {
        QSMESH_CHECK(k < f.values.size(), "report total " << name << " has no element " << k);
        return f.values[k];
      }
    QSMESH_CHECK(false, "no report field named " << name);
    return 0;
  }

  [[nodiscard]] const std::vector<FieldTotal>& fields() const { return fields_; }

  /// Writes every total into the open JSON object, in order: a number, or an array of numbers.
  void write(JsonWriter& j) const {
    for (const FieldTotal& f : fields_) {
      if (!f.array) {
        j.value(f.name, f.values[0]);
        continue;
      }
      j.begin_array(f.name);
      for (const std::int64_t v : f.values) j.value(std::string(), v);
      j.end_array();
    }
  }

 private:
  template <class R>
  void add(const R& report) {
    std::size_t at = 0;
    add_fields(report, at);
  }

  template <class R>
  void add_fields(const R& report, std::size_t& at) {
    R::fields(report, [&](const char* name, const auto& field) {
      using T = std::remove_cvref_t<decltype(field)>;
      if constexpr (parallel::HasFields<T>) {
        add_fields(field, at);
      } else if constexpr (std::is_same_v<T, bool>) {
        add_value(name, at, {field ? std::int64_t{1} : std::int64_t{0}}, false);
      } else if constexpr (std::is_integral_v<T>) {
        add_value(name, at, {static_cast<std::int64_t>(field)}, false);
      } else if constexpr (IsStdArray<T>::value) {
        if constexpr (std::is_integral_v<typename T::value_type>)
          add_value(name, at, std::vector<std::int64_t>(field.begin(), field.end()), true);
      }
    });
  }

  void add_value(const char* name, std::size_t& at, const std::vector<std::int64_t>& v,
                 bool array) {
    if (at == fields_.size())
      fields_.push_back({name, std::vector<std::int64_t>(v.size(), 0), array});
    FieldTotal& f = fields_[at++];
    for (std::size_t k = 0; k < v.size(); ++k) f.values[k] += v[k];
  }

  std::vector<FieldTotal> fields_;
};

}  // namespace qsmesh::cli
