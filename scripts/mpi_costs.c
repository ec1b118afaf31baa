/* The costs of the MPI operations qsmesh's pipeline uses, on this machine, for the scaling
 * simulation (scripts/simulate_scaling.py --comm): the latency of a small all-reduce (each stage
 * ends with one; the size map and the pattern stage add one each), of one fetch-and-add on a
 * window allocated by MPI under a passive-target lock (the dealt stages take each face so:
 * parallel::SharedCounter), of an MPI_Get (a face taken from its owner: parallel::SharedBytes), and
 * the bandwidth of point-to-point messages of a few MB (the gather on rank 0, results to owners).
 * Prints one JSON object on rank 0. Run on 2 or more ranks:
 *   mpicc -O2 -o mpi_costs scripts/mpi_costs.c && mpirun -np 2 ./mpi_costs
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) {
    fprintf(stderr, "mpi_costs: %s failed (%d)\n", what, rc);
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
}

int main(int argc, char** argv) {
  int provided = 0;
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int reps = 2000;

  /* Small all-reduce (max of one double), as StageClock::end. */
  double x = rank, y = 0;
  for (int i = 0; i < 50; ++i)
    check(MPI_Allreduce(&x, &y, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
  MPI_Barrier(MPI_COMM_WORLD);
  double t = MPI_Wtime();
  for (int i = 0; i < reps; ++i)
    check(MPI_Allreduce(&x, &y, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
  const double allreduce = (MPI_Wtime() - t) / reps;

  /* Fetch-and-add on rank 0's counter, every rank at once, as deal_out's threads do. */
  long long* base = NULL;
  MPI_Win win;
  check(MPI_Win_allocate(rank == 0 ? sizeof(long long) : 0, sizeof(long long), MPI_INFO_NULL,
                         MPI_COMM_WORLD, &base, &win),
        "MPI_Win_allocate");
  if (rank == 0) *base = 0;
  MPI_Barrier(MPI_COMM_WORLD);
  const long long one = 1;
  long long got = 0;
  t = MPI_Wtime();
  for (int i = 0; i < reps; ++i) {
    check(MPI_Win_lock(MPI_LOCK_SHARED, 0, 0, win), "MPI_Win_lock");
    check(MPI_Fetch_and_op(&one, &got, MPI_LONG_LONG, 0, 0, MPI_SUM, win), "MPI_Fetch_and_op");
    check(MPI_Win_unlock(0, win), "MPI_Win_unlock");
  }
  const double fetch = (MPI_Wtime() - t) / reps;
  MPI_Barrier(MPI_COMM_WORLD);
  check(MPI_Win_free(&win), "MPI_Win_free");

  /* MPI_Get of 64 kB from the next rank's window (a face's packed mesh is 10 kB-1 MB). */
  const int get_bytes = 1 << 16;
  char* mem = NULL;
  check(MPI_Win_allocate(get_bytes, 1, MPI_INFO_NULL, MPI_COMM_WORLD, &mem, &win),
        "MPI_Win_allocate");
  memset(mem, rank, get_bytes);
  char* buf = malloc(get_bytes);
  MPI_Barrier(MPI_COMM_WORLD);
  const int peer = (rank + 1) % size;
  t = MPI_Wtime();
  for (int i = 0; i < reps / 10; ++i) {
    check(MPI_Win_lock(MPI_LOCK_SHARED, peer, 0, win), "MPI_Win_lock");
    check(MPI_Get(buf, get_bytes, MPI_BYTE, peer, 0, get_bytes, MPI_BYTE, win), "MPI_Get");
    check(MPI_Win_unlock(peer, win), "MPI_Win_unlock");
  }
  const double get = (MPI_Wtime() - t) / (reps / 10);
  MPI_Barrier(MPI_COMM_WORLD);
  check(MPI_Win_free(&win), "MPI_Win_free");
  free(buf);

  /* Bandwidth: rank 1 sends 8 MB to rank 0, as the gather does. */
  const int big = 8 << 20;
  char* msg = malloc(big);
  memset(msg, 1, big);
  double bandwidth = 0;
  MPI_Barrier(MPI_COMM_WORLD);
  t = MPI_Wtime();
  const int rounds = 20;
  for (int i = 0; i < rounds; ++i) {
    if (rank == 0 && size > 1)
      check(MPI_Recv(msg, big, MPI_BYTE, 1, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Recv");
    else if (rank == 1)
      check(MPI_Send(msg, big, MPI_BYTE, 0, 0, MPI_COMM_WORLD), "MPI_Send");
  }
  if (size > 1) bandwidth = (double)big * rounds / (MPI_Wtime() - t);
  free(msg);

  double in[3] = {allreduce, fetch, get}, out[3];
  MPI_Reduce(in, out, 3, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  if (rank == 0)
    printf(
        "{\"ranks\": %d, \"allreduce_s\": %.3e, \"fetch_and_add_s\": %.3e, \"get_64k_s\": %.3e, "
        "\"bandwidth_bytes_per_s\": %.3e}\n",
        size, out[0], out[1], out[2], bandwidth);
  MPI_Finalize();
  return 0;
}
