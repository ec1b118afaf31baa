// Byte records of the per-face results that ranks exchange (src/parallel only): plain copies of
// trivially copyable values and vectors, read back with bounds checks.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::parallel {

template <class T>
void put(std::vector<char>& out, const T& v) {
  const auto* p = reinterpret_cast<const char*>(&v);
  out.insert(out.end(), p, p + sizeof(T));
}
template <class T>
void put_vec(std::vector<char>& out, const std::vector<T>& v) {
  put<std::int64_t>(out, static_cast<std::int64_t>(v.size()));
  const auto* p = reinterpret_cast<const char*>(v.data());
  out.insert(out.end(), p, p + v.size() * sizeof(T));
}
template <class T>
T get(const std::vector<char>& in, std::size_t& pos) {
  QSMESH_CHECK(pos + sizeof(T) <= in.size(), "truncated face record");
  T v;
  std::memcpy(&v, in.data() + pos, sizeof(T));
  pos += sizeof(T);
  return v;
}
template <class T>
void get_vec(const std::vector<char>& in, std::size_t& pos, std::vector<T>& v) {
  const auto n = static_cast<std::size_t>(get<std::int64_t>(in, pos));
  QSMESH_CHECK(pos + n * sizeof(T) <= in.size(), "truncated face record");
  v.resize(n);
  // An empty vector's data() may be null, and memcpy from or to null is undefined even for 0 bytes.
  if (n > 0) std::memcpy(v.data(), in.data() + pos, n * sizeof(T));
  pos += n * sizeof(T);
}

inline void put_string(std::vector<char>& out, const std::string& text) {
  put_vec(out, std::vector<char>(text.begin(), text.end()));
}

inline std::string get_string(const std::vector<char>& in, std::size_t& pos) {
  std::vector<char> text;
  get_vec(in, pos, text);
  return {text.begin(), text.end()};
}

inline void pack_mesh(const mesh::FaceMesh& m, std::vector<char>& out) {
  put<LO>(out, m.face);
  put_vec(out, m.points);
  put_vec(out, m.uv);
  put_vec(out, m.vclass);
  put_vec(out, m.triangles);
  put_vec(out, m.quads);
}

inline void unpack_mesh(const std::vector<char>& in, std::size_t& pos, mesh::FaceMesh& m) {
  m.face = get<LO>(in, pos);
  get_vec(in, pos, m.points);
  get_vec(in, pos, m.uv);
  get_vec(in, pos, m.vclass);
  get_vec(in, pos, m.triangles);
  get_vec(in, pos, m.quads);
}

}  // namespace qsmesh::parallel
