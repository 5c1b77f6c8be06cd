// The batched exchange of the eleven FSI fields (u, v, w, p with halo 1; phi and the six
// Bt components with halo 3) on a 64^3 block per rank, ranks side by side in x, sync and
// async, beside a plain MPI_Send/MPI_Recv ping-pong of the same bytes between ranks 0, 1.
//
//   mpirun -n 2 build/bin/bench_halo_exchange --benchmark_min_time=1
//
// Counters: bytes_per_second = bytes this rank sends through MPI per exchange / time
// (local self-copies excluded); mpi_bytes, local_bytes per exchange for reference.
#include <mpi.h>

#include <memory>
#include <vector>

#include "decomposition.hpp"
#include "field.hpp"
#include "halo_exchange.hpp"
#include "mpi_benchmark.hpp"

namespace {

using namespace efsi;

std::vector<FieldSpec> fsi_fields() {
  return {
      {"u", Stagger::face_x, 1, WallParity::odd},      {"v", Stagger::face_y, 1, WallParity::odd},
      {"w", Stagger::face_z, 1, WallParity::odd},      {"p", Stagger::cell, 1, WallParity::even},
      {"phi", Stagger::cell, 3, WallParity::even},     {"Bt11", Stagger::cell, 3, WallParity::even},
      {"Bt22", Stagger::cell, 3, WallParity::even},    {"Bt33", Stagger::cell, 3, WallParity::even},
      {"Bt12", Stagger::edge_xy, 3, WallParity::even}, {"Bt13", Stagger::edge_xz, 3, WallParity::even},
      {"Bt23", Stagger::edge_yz, 3, WallParity::even},
  };
}

struct Setup {
  std::unique_ptr<CartDecomposition> dec;
  std::vector<std::unique_ptr<Field>> fields;
  std::unique_ptr<HaloExchange> halo;
  RegionTimers timers;
  explicit Setup(int n) {
    int p = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &p);
    dec = std::make_unique<CartDecomposition>(MPI_COMM_WORLD, Int3{n * p, n, n}, 3, Int3{p, 1, 1});
    std::vector<Field*> ptrs;
    for (const auto& s : fsi_fields()) {
      fields.push_back(std::make_unique<Field>(*dec, s));
      fields.back()->fill(1.0 + dec->rank());
      ptrs.push_back(fields.back().get());
    }
    halo = std::make_unique<HaloExchange>(*dec, ptrs, Reach::full, &timers);
  }
};

// Per-exchange breakdown on rank 0 (us): where the time goes besides the wire.
void report(benchmark::State& state, Setup& s) {
  const HaloExchange& h = *s.halo;
  const double per = 1e6 / static_cast<double>(state.iterations());
  state.counters["pack_us"] = s.timers.get(Region::halo_pack) * per;
  state.counters["mpi_us"] = (s.timers.get(Region::halo_mpi) + s.timers.get(Region::halo_wait)) * per;
  state.counters["unpack_us"] = s.timers.get(Region::halo_unpack) * per;
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(h.bytes_sent_mpi()));
  state.counters["mpi_bytes"] = static_cast<double>(h.bytes_sent_mpi());
  state.counters["local_bytes"] = static_cast<double>(h.bytes_copied_local());
  state.counters["messages"] = h.messages_sent();
}

void BM_HaloSync(benchmark::State& state) {
  Setup s(static_cast<int>(state.range(0)));
  s.halo->exchange();  // warm-up, outside the timers
  s.timers.reset();
  for (auto _ : state) state.SetIterationTime(bench::max_over_ranks(MPI_COMM_WORLD, [&] { s.halo->exchange(); }));
  report(state, s);
}

void BM_HaloAsync(benchmark::State& state) {
  Setup s(static_cast<int>(state.range(0)));
  s.halo->begin();
  s.halo->finish();
  s.timers.reset();
  for (auto _ : state)
    state.SetIterationTime(bench::max_over_ranks(MPI_COMM_WORLD, [&] {
      s.halo->begin();
      s.halo->finish();
    }));
  report(state, s);
}

// Ranks 0 and 1 bounce the bytes one rank sends per exchange; half a round trip is the
// time to move them one way, which is what each rank does (both ways at once) in the
// exchange.  Other ranks idle.
void BM_PingPong(benchmark::State& state) {
  int rank = 0, p = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  if (p < 2) {
    state.SkipWithError("ping-pong needs at least 2 ranks");
    for (auto _ : state) {
    }
    return;
  }
  Setup s(static_cast<int>(state.range(0)));
  const std::size_t count = s.halo->bytes_sent_mpi() / sizeof(double);
  std::vector<double> buf(count, 1.0);
  const int n = static_cast<int>(count);
  for (auto _ : state) {
    const double t = bench::max_over_ranks(MPI_COMM_WORLD, [&] {
      if (rank == 0) {
        MPI_Send(buf.data(), n, MPI_DOUBLE, 1, 0, MPI_COMM_WORLD);
        MPI_Recv(buf.data(), n, MPI_DOUBLE, 1, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      } else if (rank == 1) {
        MPI_Recv(buf.data(), n, MPI_DOUBLE, 0, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        MPI_Send(buf.data(), n, MPI_DOUBLE, 0, 0, MPI_COMM_WORLD);
      }
    });
    state.SetIterationTime(t / 2);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(count * sizeof(double)));
  state.counters["mpi_bytes"] = static_cast<double>(count * sizeof(double));
}

BENCHMARK(BM_HaloSync)->Arg(64)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HaloAsync)->Arg(64)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PingPong)->Arg(64)->UseManualTime()->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) { return efsi::bench::run_main(argc, argv); }
