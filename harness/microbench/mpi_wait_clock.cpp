#include "mpi_wait_clock.hpp"

#include <mpi.h>

#include <cstdlib>
#include <cstring>

#include "kernel_clock.hpp"

namespace efsi::bench {
namespace {

double g_wait_cpu = 0.0;  // MPI is called from one thread per rank (MPI_THREAD_FUNNELED)
bool g_on = false;

struct WaitScope {
  double start = g_on ? cpu_seconds() : 0.0;
  ~WaitScope() {
    if (g_on) g_wait_cpu += cpu_seconds() - start;
  }
};

}  // namespace

double mpi_wait_cpu_seconds() { return g_wait_cpu; }

bool mpi_wait_clock_requested() {
  const char* v = std::getenv("EFSI_MPI_WAIT_CLOCK");
  return v && std::strcmp(v, "1") == 0;
}

void set_mpi_wait_clock(bool on) { g_on = on; }

}  // namespace efsi::bench

using efsi::bench::WaitScope;

extern "C" {

int MPI_Sendrecv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, int dest, int sendtag, void* recvbuf,
                 int recvcount, MPI_Datatype recvtype, int source, int recvtag, MPI_Comm comm, MPI_Status* status) {
  WaitScope w;
  return PMPI_Sendrecv(sendbuf, sendcount, sendtype, dest, sendtag, recvbuf, recvcount, recvtype, source, recvtag,
                       comm, status);
}

int MPI_Waitall(int count, MPI_Request requests[], MPI_Status statuses[]) {
  WaitScope w;
  return PMPI_Waitall(count, requests, statuses);
}

int MPI_Allreduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype datatype, MPI_Op op, MPI_Comm comm) {
  WaitScope w;
  return PMPI_Allreduce(sendbuf, recvbuf, count, datatype, op, comm);
}

int MPI_Alltoallv(const void* sendbuf, const int sendcounts[], const int sdispls[], MPI_Datatype sendtype,
                  void* recvbuf, const int recvcounts[], const int rdispls[], MPI_Datatype recvtype, MPI_Comm comm) {
  WaitScope w;
  return PMPI_Alltoallv(sendbuf, sendcounts, sdispls, sendtype, recvbuf, recvcounts, rdispls, recvtype, comm);
}

}  // extern "C"
