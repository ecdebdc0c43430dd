#pragma once
// What the multi-rank tests (run under mpirun with tests/sim/mpi_test_main.cpp) share: this
// process's rank, the rank count, and a folder every rank sees.
#include <mpi.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace strata::test {

inline int worldRank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
inline int worldSize() {
  int n = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

/// A fresh folder under the temporary directory, made by rank 0 and its name sent to the others
/// (collective): `prefix-<ranks>-<rank 0's pid>`.
inline std::filesystem::path sharedTempDir(const std::string& prefix) {
  std::string path;
  if (worldRank() == 0) {
    path = (std::filesystem::temp_directory_path() /
            (prefix + "-" + std::to_string(worldSize()) + "-" + std::to_string(::getpid())))
               .string();
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  int len = int(path.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, MPI_COMM_WORLD);
  path.resize(size_t(len));
  MPI_Bcast(path.data(), len, MPI_CHAR, 0, MPI_COMM_WORLD);
  return path;
}

}  // namespace strata::test
