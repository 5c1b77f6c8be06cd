#include <benchmark/benchmark.h>
#include <mpi.h>

#include <cstring>

#include "mpi_benchmark.hpp"
#include "runtime.hpp"

namespace efsi::bench {
namespace {

class NullReporter : public benchmark::BenchmarkReporter {
 public:
  bool ReportContext(const Context&) override { return true; }
  void ReportRuns(const std::vector<Run>&) override {}
};

}  // namespace

int run_main(int argc, char** argv, const std::function<void()>& before_finalize) {
  efsi::Runtime runtime(argc, argv);
  // Only rank 0 writes --benchmark_out; the others drop the option before parsing.
  if (runtime.rank() != 0) {
    int kept = 1;
    for (int a = 1; a < argc; ++a)
      if (std::strncmp(argv[a], "--benchmark_out", 15) != 0) argv[kept++] = argv[a];
    argc = kept;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  int nranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &nranks);
  benchmark::AddCustomContext("mpi_ranks", std::to_string(nranks));
  benchmark::AddCustomContext("omp_threads", std::to_string(efsi::max_threads()));
  benchmark::AddCustomContext("efsi_build", EFSI_BUILD_CONFIG);
  if (runtime.rank() == 0) {
    benchmark::RunSpecifiedBenchmarks();
  } else {
    NullReporter display;
    benchmark::RunSpecifiedBenchmarks(&display);
  }
  benchmark::Shutdown();
  if (before_finalize) before_finalize();
  return 0;
}

}  // namespace efsi::bench
