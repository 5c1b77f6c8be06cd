#include "mpi_interpose.hpp"

#include <mpi.h>

namespace efsi {
namespace {

MpiCensus g_census;
double g_seconds = 0.0;
void (*g_hook)() = nullptr;

// One wrapped call: the hook around it, its time added to g_seconds.
struct InsideMpi {
  explicit InsideMpi(bool timed = true) : timed_(timed) {
    if (g_hook) g_hook();
    if (timed_) t0_ = PMPI_Wtime();
  }
  ~InsideMpi() {
    if (timed_) g_seconds += PMPI_Wtime() - t0_;
    if (g_hook) g_hook();
  }
  InsideMpi(const InsideMpi&) = delete;
  InsideMpi& operator=(const InsideMpi&) = delete;

 private:
  bool timed_;
  double t0_ = 0.0;
};

long long type_bytes(MPI_Datatype t) {
  int size = 0;
  PMPI_Type_size(t, &size);
  return size;
}

void count_send(int count, MPI_Datatype t, int dest, MPI_Comm comm) {
  if (dest == MPI_PROC_NULL) return;
  int me = 0;
  PMPI_Comm_rank(comm, &me);
  if (dest == me) return;
  ++g_census.messages;
  g_census.bytes += count * type_bytes(t);
}

void count_collective(long long bytes) {
  ++g_census.collectives;
  g_census.collective_bytes += bytes;
}

long long to_others(const int counts[], MPI_Comm comm) {
  int size = 1, me = 0;
  PMPI_Comm_size(comm, &size);
  PMPI_Comm_rank(comm, &me);
  long long n = 0;
  for (int r = 0; r < size; ++r)
    if (r != me) n += counts[r];
  return n;
}

}  // namespace

MpiCensus operator-(const MpiCensus& a, const MpiCensus& b) {
  return {a.messages - b.messages, a.bytes - b.bytes, a.collectives - b.collectives,
          a.collective_bytes - b.collective_bytes};
}

MpiCensus operator+(const MpiCensus& a, const MpiCensus& b) {
  return {a.messages + b.messages, a.bytes + b.bytes, a.collectives + b.collectives,
          a.collective_bytes + b.collective_bytes};
}

MpiCensus mpi_census() { return g_census; }
double mpi_seconds() { return g_seconds; }
void set_mpi_call_hook(void (*hook)()) { g_hook = hook; }

}  // namespace efsi

using efsi::InsideMpi;

extern "C" {

int MPI_Isend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm, MPI_Request* req) {
  InsideMpi in;
  efsi::count_send(count, type, dest, comm);
  return PMPI_Isend(buf, count, type, dest, tag, comm, req);
}

int MPI_Send(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm) {
  InsideMpi in;
  efsi::count_send(count, type, dest, comm);
  return PMPI_Send(buf, count, type, dest, tag, comm);
}

int MPI_Irecv(void* buf, int count, MPI_Datatype type, int source, int tag, MPI_Comm comm, MPI_Request* req) {
  InsideMpi in;
  return PMPI_Irecv(buf, count, type, source, tag, comm, req);
}

int MPI_Recv(void* buf, int count, MPI_Datatype type, int source, int tag, MPI_Comm comm, MPI_Status* status) {
  InsideMpi in;
  return PMPI_Recv(buf, count, type, source, tag, comm, status);
}

int MPI_Sendrecv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, int dest, int sendtag, void* recvbuf,
                 int recvcount, MPI_Datatype recvtype, int source, int recvtag, MPI_Comm comm, MPI_Status* status) {
  InsideMpi in;
  efsi::count_send(sendcount, sendtype, dest, comm);
  return PMPI_Sendrecv(sendbuf, sendcount, sendtype, dest, sendtag, recvbuf, recvcount, recvtype, source, recvtag,
                       comm, status);
}

int MPI_Wait(MPI_Request* request, MPI_Status* status) {
  InsideMpi in;
  return PMPI_Wait(request, status);
}

int MPI_Waitall(int count, MPI_Request requests[], MPI_Status statuses[]) {
  InsideMpi in;
  return PMPI_Waitall(count, requests, statuses);
}

int MPI_Waitany(int count, MPI_Request requests[], int* index, MPI_Status* status) {
  InsideMpi in;
  return PMPI_Waitany(count, requests, index, status);
}

int MPI_Test(MPI_Request* request, int* flag, MPI_Status* status) {
  InsideMpi in;
  return PMPI_Test(request, flag, status);
}

int MPI_Testall(int count, MPI_Request requests[], int* flag, MPI_Status statuses[]) {
  InsideMpi in;
  return PMPI_Testall(count, requests, flag, statuses);
}

int MPI_Allreduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm) {
  InsideMpi in;
  efsi::count_collective(count * efsi::type_bytes(type));
  return PMPI_Allreduce(sendbuf, recvbuf, count, type, op, comm);
}

int MPI_Alltoallv(const void* sendbuf, const int sendcounts[], const int sdispls[], MPI_Datatype sendtype,
                  void* recvbuf, const int recvcounts[], const int rdispls[], MPI_Datatype recvtype, MPI_Comm comm) {
  InsideMpi in;
  efsi::count_collective(efsi::to_others(sendcounts, comm) * efsi::type_bytes(sendtype));
  return PMPI_Alltoallv(sendbuf, sendcounts, sdispls, sendtype, recvbuf, recvcounts, rdispls, recvtype, comm);
}

int MPI_Bcast(void* buf, int count, MPI_Datatype type, int root, MPI_Comm comm) {
  InsideMpi in;
  efsi::count_collective(count * efsi::type_bytes(type));
  return PMPI_Bcast(buf, count, type, root, comm);
}

int MPI_Barrier(MPI_Comm comm) {
  InsideMpi in;
  efsi::count_collective(0);
  return PMPI_Barrier(comm);
}

double MPI_Wtime() {
  InsideMpi in(false);
  return PMPI_Wtime();
}

}  // extern "C"
