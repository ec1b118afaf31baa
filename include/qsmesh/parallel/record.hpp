// Byte records of per-face values, for the exchanges between ranks. A record type declares its
// fields once, in a static member template
//
//   template <class S, class V> static void fields(S& self, V&& visit) {
//     visit("ok", self.ok);
//     visit("quads", self.quads);
//   }
//
// (S is the type itself or its const version, so one list serves reading and writing). The
// exchange packs and unpacks every field in that order (write_record / read_record); the drivers'
// writers can list the same fields by name. Adding a field to a report is then one line in its
// fields(). No MPI here: these are plain byte buffers, tested without mpirun.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/core/types.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::parallel {

namespace detail {
// A visitor that accepts any field: the probe of HasFields.
struct AnyField {
  template <class M>
  void operator()(const char*, M&) const {}
};
template <class T>
struct IsVector : std::false_type {};
template <class T, class A>
struct IsVector<std::vector<T, A>> : std::true_type {};
}  // namespace detail

/// A type that lists its fields with a static fields(self, visit) (see the top of this file).
template <class T>
concept HasFields = requires(T& t) {
  T::fields(t, detail::AnyField{});
};

/// Appends the bytes of a trivially copyable value.
template <class T>
void put(std::vector<char>& out, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  const auto* p = reinterpret_cast<const char*>(&v);
  out.insert(out.end(), p, p + sizeof(T));
}
/// Appends a vector of trivially copyable values: its size (64-bit), then its bytes.
template <class T>
void put_vec(std::vector<char>& out, const std::vector<T>& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  put<std::int64_t>(out, static_cast<std::int64_t>(v.size()));
  const auto* p = reinterpret_cast<const char*>(v.data());
  out.insert(out.end(), p, p + v.size() * sizeof(T));
}
/// Reads a value written by put at `pos` and advances `pos`; throws qsmesh::Error when the buffer
/// ends first.
template <class T>
T get(const std::vector<char>& in, std::size_t& pos) {
  static_assert(std::is_trivially_copyable_v<T>);
  QSMESH_CHECK(pos + sizeof(T) <= in.size(), "truncated face record");
  T v;
  std::memcpy(&v, in.data() + pos, sizeof(T));
  pos += sizeof(T);
  return v;
}
/// Reads a vector written by put_vec (bounds checked as get).
template <class T>
void get_vec(const std::vector<char>& in, std::size_t& pos, std::vector<T>& v) {
  const auto n = static_cast<std::size_t>(get<std::int64_t>(in, pos));
  QSMESH_CHECK(n <= in.size() && pos + n * sizeof(T) <= in.size(), "truncated face record");
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

/// Appends any value a record may hold: a record (its fields in order), bool (one byte), a
/// string, a FaceMesh, a vector or array (of any of these), or a trivially copyable value.
template <class T>
void write_record(std::vector<char>& out, const T& v) {
  if constexpr (HasFields<T>) {
    T::fields(v, [&](const char*, const auto& field) { write_record(out, field); });
  } else if constexpr (std::is_same_v<T, bool>) {
    put<std::uint8_t>(out, v ? 1 : 0);
  } else if constexpr (std::is_same_v<T, std::string>) {
    put_string(out, v);
  } else if constexpr (std::is_same_v<T, mesh::FaceMesh>) {
    pack_mesh(v, out);
  } else if constexpr (detail::IsVector<T>::value) {
    using E = typename T::value_type;
    if constexpr (std::is_trivially_copyable_v<E> && !std::is_same_v<E, bool>) {
      put_vec(out, v);
    } else {
      put<std::int64_t>(out, static_cast<std::int64_t>(v.size()));
      for (const auto& e : v) write_record(out, e);
    }
  } else if constexpr (IsStdArray<T>::value) {
    for (const auto& e : v) write_record(out, e);
  } else {
    put(out, v);
  }
}

/// The number of bytes write_record(out, v) appends, counted without writing them (what an
/// exchange of `v` moves, for --stats and the scaling simulation on runs that send nothing).
template <class T>
std::int64_t record_bytes(const T& v) {
  if constexpr (HasFields<T>) {
    std::int64_t n = 0;
    T::fields(v, [&](const char*, const auto& field) { n += record_bytes(field); });
    return n;
  } else if constexpr (std::is_same_v<T, bool>) {
    return sizeof(std::uint8_t);
  } else if constexpr (std::is_same_v<T, std::string>) {
    return sizeof(std::int64_t) + static_cast<std::int64_t>(v.size());
  } else if constexpr (std::is_same_v<T, mesh::FaceMesh>) {
    auto vec = [](const auto& x) {
      return sizeof(std::int64_t) +
             x.size() * sizeof(typename std::decay_t<decltype(x)>::value_type);
    };
    return static_cast<std::int64_t>(sizeof(LO) + vec(v.points) + vec(v.uv) + vec(v.vclass) +
                                     vec(v.triangles) + vec(v.quads));
  } else if constexpr (detail::IsVector<T>::value) {
    using E = typename T::value_type;
    if constexpr (std::is_trivially_copyable_v<E> && !std::is_same_v<E, bool>) {
      return static_cast<std::int64_t>(sizeof(std::int64_t) + v.size() * sizeof(E));
    } else {
      std::int64_t n = sizeof(std::int64_t);
      for (const auto& e : v) n += record_bytes(e);
      return n;
    }
  } else if constexpr (IsStdArray<T>::value) {
    std::int64_t n = 0;
    for (const auto& e : v) n += record_bytes(e);
    return n;
  } else {
    static_assert(std::is_trivially_copyable_v<T>);
    return sizeof(T);
  }
}

/// Reads a value written by write_record at `pos` into `v` and advances `pos`; throws
/// qsmesh::Error on a truncated buffer.
template <class T>
void read_record(const std::vector<char>& in, std::size_t& pos, T& v) {
  if constexpr (HasFields<T>) {
    T::fields(v, [&](const char*, auto& field) { read_record(in, pos, field); });
  } else if constexpr (std::is_same_v<T, bool>) {
    v = get<std::uint8_t>(in, pos) != 0;
  } else if constexpr (std::is_same_v<T, std::string>) {
    v = get_string(in, pos);
  } else if constexpr (std::is_same_v<T, mesh::FaceMesh>) {
    unpack_mesh(in, pos, v);
  } else if constexpr (detail::IsVector<T>::value) {
    using E = typename T::value_type;
    if constexpr (std::is_trivially_copyable_v<E> && !std::is_same_v<E, bool>) {
      get_vec(in, pos, v);
    } else {
      const auto n = static_cast<std::size_t>(get<std::int64_t>(in, pos));
      QSMESH_CHECK(n <= in.size() - pos, "truncated face record");  // each element is >= 1 byte
      v.assign(n, E{});
      for (auto& e : v) read_record(in, pos, e);
    }
  } else if constexpr (IsStdArray<T>::value) {
    for (auto& e : v) read_record(in, pos, e);
  } else {
    v = get<T>(in, pos);
  }
}

}  // namespace qsmesh::parallel
