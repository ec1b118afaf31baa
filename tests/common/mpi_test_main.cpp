// main() of the MPI test executables (qsmesh_add_mpi_test): GoogleTest inside one MPI session.
#include <gtest/gtest.h>
#include <mpi.h>

#include "qsmesh/parallel/comm.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  qsmesh::parallel::MpiSession mpi(&argc, &argv);
  // Only rank 0 prints the gtest report; failures on other ranks still fail the exit code.
  if (qsmesh::parallel::Comm::world().rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  int failed = RUN_ALL_TESTS();
  int any = 0;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return any;
}
