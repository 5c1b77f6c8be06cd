#include "mpi_interpose.hpp"

#include <mpi.h>

#include "callgrind_region.hpp"

namespace efsi::bench {
namespace {

MpiCensus g_census;
bool g_uncollected = false;

// Collection off for the duration of one wrapped call (collective or not, MPI's time is
// MPI's, not the kernel's).
struct OutsideCounts {
  bool active = g_uncollected;
  OutsideCounts() {
    if (active) callgrind_toggle_collect();
  }
  ~OutsideCounts() {
    if (active) callgrind_toggle_collect();
  }
  OutsideCounts(const OutsideCounts&) = delete;
  OutsideCounts& operator=(const OutsideCounts&) = delete;
};

long long type_bytes(MPI_Datatype t) {
  int size = 0;
  PMPI_Type_size(t, &size);
  return size;
}

bool to_other_rank(int dest, MPI_Comm comm) {
  if (dest == MPI_PROC_NULL) return false;
  int me = 0;
  PMPI_Comm_rank(comm, &me);
  return dest != me;
}

void count_send(int count, MPI_Datatype t, int dest, MPI_Comm comm) {
  if (!to_other_rank(dest, comm)) return;
  ++g_census.messages;
  g_census.bytes += count * type_bytes(t);
}

void count_collective(long long bytes) {
  ++g_census.collectives;
  g_census.collective_bytes += bytes;
}

}  // namespace

MpiCensus operator-(const MpiCensus& a, const MpiCensus& b) {
  return {a.messages - b.messages, a.bytes - b.bytes, a.collectives - b.collectives,
          a.collective_bytes - b.collective_bytes};
}

MpiCensus mpi_census() { return g_census; }

void set_mpi_uncollected(bool on) { g_uncollected = on; }

}  // namespace efsi::bench

using efsi::bench::OutsideCounts;

extern "C" {

int MPI_Isend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm, MPI_Request* req) {
  OutsideCounts o;
  efsi::bench::count_send(count, type, dest, comm);
  return PMPI_Isend(buf, count, type, dest, tag, comm, req);
}

int MPI_Irecv(void* buf, int count, MPI_Datatype type, int source, int tag, MPI_Comm comm, MPI_Request* req) {
  OutsideCounts o;
  return PMPI_Irecv(buf, count, type, source, tag, comm, req);
}

int MPI_Sendrecv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, int dest, int sendtag, void* recvbuf,
                 int recvcount, MPI_Datatype recvtype, int source, int recvtag, MPI_Comm comm, MPI_Status* status) {
  OutsideCounts o;
  efsi::bench::count_send(sendcount, sendtype, dest, comm);
  return PMPI_Sendrecv(sendbuf, sendcount, sendtype, dest, sendtag, recvbuf, recvcount, recvtype, source, recvtag,
                       comm, status);
}

int MPI_Waitall(int count, MPI_Request requests[], MPI_Status statuses[]) {
  OutsideCounts o;
  return PMPI_Waitall(count, requests, statuses);
}

int MPI_Testall(int count, MPI_Request requests[], int* flag, MPI_Status statuses[]) {
  OutsideCounts o;
  return PMPI_Testall(count, requests, flag, statuses);
}

int MPI_Allreduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm) {
  OutsideCounts o;
  efsi::bench::count_collective(count * efsi::bench::type_bytes(type));
  return PMPI_Allreduce(sendbuf, recvbuf, count, type, op, comm);
}

int MPI_Alltoallv(const void* sendbuf, const int sendcounts[], const int sdispls[], MPI_Datatype sendtype,
                  void* recvbuf, const int recvcounts[], const int rdispls[], MPI_Datatype recvtype, MPI_Comm comm) {
  OutsideCounts o;
  int size = 1, me = 0;
  PMPI_Comm_size(comm, &size);
  PMPI_Comm_rank(comm, &me);
  long long sent = 0;
  for (int r = 0; r < size; ++r)
    if (r != me) sent += sendcounts[r];
  efsi::bench::count_collective(sent * efsi::bench::type_bytes(sendtype));
  return PMPI_Alltoallv(sendbuf, sendcounts, sdispls, sendtype, recvbuf, recvcounts, rdispls, recvtype, comm);
}

int MPI_Bcast(void* buf, int count, MPI_Datatype type, int root, MPI_Comm comm) {
  OutsideCounts o;
  efsi::bench::count_collective(count * efsi::bench::type_bytes(type));
  return PMPI_Bcast(buf, count, type, root, comm);
}

int MPI_Barrier(MPI_Comm comm) {
  OutsideCounts o;
  efsi::bench::count_collective(0);
  return PMPI_Barrier(comm);
}

double MPI_Wtime() {
  OutsideCounts o;
  return PMPI_Wtime();
}

}  // extern "C"
