#pragma once
/// Private to fem_reference: byte buffers for what rank 0 sends the other MPI ranks (a mesh, a
/// rank's part). All ranks run the same binary, so raw PODs are fine. Free of deal.II.
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel::fem::detail {

struct ByteWriter {
  std::vector<char> bytes;
  template <class T>
  void pod(const T& v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    pod<std::uint64_t>(v.size());
    const auto* p = reinterpret_cast<const char*>(v.data());
    bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
  }
  void string(const std::string& s) { array(std::vector<char>(s.begin(), s.end())); }
};

struct ByteReader {
  const std::vector<char>& bytes;
  std::size_t at = 0;
  template <class T>
  T pod() {
    T v;
    std::memcpy(static_cast<void*>(&v), bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  template <class T>
  std::vector<T> array() {
    const auto n = pod<std::uint64_t>();
    std::vector<T> v(n);
    std::memcpy(static_cast<void*>(v.data()), bytes.data() + at, n * sizeof(T));
    at += n * sizeof(T);
    return v;
  }
  std::string string() {
    const auto c = array<char>();
    return {c.begin(), c.end()};
  }
};

/// MPI counts are int: large buffers go in chunks of 1 GiB.
inline constexpr std::uint64_t kMpiChunk = 1u << 30;

/// MPI_Bcast of a byte buffer from `root` (the size first).
inline void broadcast_bytes(std::vector<char>& bytes, int root, MPI_Comm comm) {
  std::uint64_t n = bytes.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, root, comm);
  bytes.resize(n);
  for (std::uint64_t at = 0; at < n; at += kMpiChunk) {
    const int count = static_cast<int>(std::min(kMpiChunk, n - at));
    MPI_Bcast(bytes.data() + at, count, MPI_CHAR, root, comm);
  }
}

/// Point-to-point send of a byte buffer (the size first); receive it with receive_bytes.
inline void send_bytes(const std::vector<char>& bytes, int to, int tag, MPI_Comm comm) {
  const std::uint64_t n = bytes.size();
  MPI_Send(&n, 1, MPI_UINT64_T, to, tag, comm);
  for (std::uint64_t at = 0; at < n; at += kMpiChunk) {
    const int count = static_cast<int>(std::min(kMpiChunk, n - at));
    MPI_Send(bytes.data() + at, count, MPI_CHAR, to, tag, comm);
  }
}

inline std::vector<char> receive_bytes(int from, int tag, MPI_Comm comm) {
  std::uint64_t n = 0;
  MPI_Recv(&n, 1, MPI_UINT64_T, from, tag, comm, MPI_STATUS_IGNORE);
  std::vector<char> bytes(n);
  for (std::uint64_t at = 0; at < n; at += kMpiChunk) {
    const int count = static_cast<int>(std::min(kMpiChunk, n - at));
    MPI_Recv(bytes.data() + at, count, MPI_CHAR, from, tag, comm, MPI_STATUS_IGNORE);
  }
  return bytes;
}

/// A TetMesh's nodes, elements and groups, written and read in the same order.
inline void write_mesh(ByteWriter& w, const TetMesh& m) {
  w.array(m.nodes);
  w.array(m.tets);
  w.array(m.triangles);
  w.pod<std::uint64_t>(m.groups.size());
  for (const auto& g : m.groups) {
    w.string(g.name);
    w.pod(g.dim);
    w.pod(g.tag);
    w.array(g.elements);
  }
}

inline TetMesh read_mesh(ByteReader& r) {
  TetMesh m;
  m.nodes = r.array<Vec3>();
  m.tets = r.array<Tet>();
  m.triangles = r.array<Triangle>();
  const auto n_groups = r.pod<std::uint64_t>();
  for (std::uint64_t i = 0; i < n_groups; ++i) {
    PhysicalGroup g;
    g.name = r.string();
    g.dim = r.pod<int>();
    g.tag = r.pod<int>();
    g.elements = r.array<int>();
    m.groups.push_back(std::move(g));
  }
  return m;
}

}  // namespace vessel::fem::detail
