// A small streaming JSON writer for the driver's --json and --stats outputs.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace qsmesh::cli {

class JsonWriter {
 public:
  JsonWriter& begin_object(const std::string& key = {});
  JsonWriter& end_object();
  JsonWriter& begin_array(const std::string& key = {});
  JsonWriter& end_array();
  JsonWriter& value(const std::string& key, const std::string& v);
  JsonWriter& value(const std::string& key, const char* v) { return value(key, std::string(v)); }
  JsonWriter& value(const std::string& key, double v);
  JsonWriter& value(const std::string& key, std::int64_t v);
  JsonWriter& value(const std::string& key, int v) {
    return value(key, static_cast<std::int64_t>(v));
  }
  JsonWriter& value(const std::string& key, bool v);
  /// An array of numbers, on one line.
  JsonWriter& value(const std::string& key, const std::vector<double>& v);
  [[nodiscard]] const std::string& str() const { return out_; }

 private:
  void key_prefix(const std::string& key);
  void newline();
  static std::string escape(const std::string& s);
  std::string out_;
  std::vector<bool> first_;  ///< per open container: no element written yet
};

}  // namespace qsmesh::cli
