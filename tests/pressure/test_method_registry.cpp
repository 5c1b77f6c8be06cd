// The pressure-method registry (method_registry.hpp): every registered method is found by
// name, takes only its own options with their checks, resolves the paper's defaults, and
// builds a solver that steps in both halo modes; the regions the methods define are named
// and flagged as the comm figure needs.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <set>
#include <string>

#include "channel_case.hpp"
#include "mpi_test_support.hpp"

using namespace efsi;
using namespace efsi::testing;

TEST(MethodRegistry, NamesAreUniqueAndFound) {
  std::set<std::string> names;
  for (const MethodSpec* m : pressure_methods()) {
    EXPECT_TRUE(names.insert(m->name()).second) << m->name() << " registered twice";
    EXPECT_EQ(&find_method(m->name()), m);
    EXPECT_NE(describe_methods().find("method " + m->name() + "|"), std::string::npos);
  }
  for (const char* n : {"acm", "sor", "fft"}) EXPECT_TRUE(names.count(n)) << n;
  const std::string msg = config_error_of([] { find_method("mg2"); });
  EXPECT_NE(msg.find("'mg2'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(method_names()), std::string::npos) << msg;
}

TEST(MethodRegistry, OptionsBelongToTheirMethods) {
  EXPECT_NE(config_error_of([] { configure_method("acm", {{"--ns", 40}}, std::nullopt); })
                .find("--ns applies to --method sor only"),
            std::string::npos);
  EXPECT_NE(config_error_of([] { configure_method("sor", {{"--ns", 4.5}}, std::nullopt); }).find("whole number"),
            std::string::npos);
  EXPECT_NE(config_error_of([] { configure_method("sor", {{"--ns", 0}}, std::nullopt); }).find("at least 1"),
            std::string::npos);
  EXPECT_NE(config_error_of([] { configure_method("sor", {{"--eps", 1.5}}, std::nullopt); }).find("(0, 1)"),
            std::string::npos);
  EXPECT_NE(config_error_of([] { configure_method("fft", {}, -1); }).find("--nc -1"), std::string::npos);
}

TEST(MethodRegistry, SorResolvesThePapersDefaults) {
  const MethodChoice d = configure_method("sor", {}, std::nullopt);
  EXPECT_EQ(d.value("ns"), paper::kCalibratedSorSweeps[0].sweeps);
  EXPECT_EQ(d.cn_sweeps, paper::kCnSweeps);
  EXPECT_EQ(d.report.at("eps"), "0.001");
  EXPECT_EQ(d.report.at("ns_per_step"), std::to_string(paper::kCalibratedSorSweeps[0].sweeps));
  EXPECT_EQ(configure_method("sor", {{"--eps", 1e-4}}, std::nullopt).value("ns"), paper::kCalibratedSorSweeps[1].sweeps);
  const MethodChoice n = configure_method("sor", {{"--ns", 40}}, 3);
  EXPECT_EQ(n.value("ns"), 40);
  EXPECT_EQ(n.cn_sweeps, 3);
  EXPECT_EQ(n.report.count("eps"), 0u) << "--ns alone chose N_S: no eps in the CSV";
  EXPECT_NE(config_error_of([] { configure_method("sor", {{"--eps", 1e-5}}, std::nullopt); }).find("give --ns"),
            std::string::npos);
  EXPECT_EQ(configure_method("acm", {}, std::nullopt).cn_sweeps, 0);
  EXPECT_EQ(configure_method("fft", {}, std::nullopt).cn_sweeps, 0);
}

TEST(MethodRegistry, EveryMethodStepsInBothHaloModes) {
  const int p = world_size();
  for (const MethodSpec* m : pressure_methods())
    for (CommMode mode : {CommMode::sync, CommMode::async}) {
      if (!m->supports(mode)) continue;
      SCOPED_TRACE(m->name() + "/" + to_string(mode));
      ChannelCase c = weak_block_case(32, p);
      c.solver.dt = m->scaling_defaults().dt;
      c.solver.comm = mode;
      OptionValues given;
      if (m->name() == "sor") given["--ns"] = 8;
      choose_method(c, configure_method(m->name(), given, 2));
      c.timed_planning = false;
      const auto particles = validate_case(c, p, 100 * c.solver.dt);
      CartDecomposition dec(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, c.forced_dims);
      auto solver = build_solver(c, dec, particles);
      solver->impose_laminar_flow();
      for (int s = 0; s < 3; ++s) solver->step();
      const FlowDiagnostics d = solver->diagnostics();
      EXPECT_TRUE(std::isfinite(d.kinetic));
      EXPECT_GT(d.kinetic, 0.0);
      EXPECT_LT(d.div_max, 1e-2 * d.u_max / c.domain.spacing(X));
    }
}

TEST(MethodRegistry, MethodRegionsAreNamedAndFlagged) {
  std::set<std::string> compute, comm;
  for (int r = 6; r < region_count(); ++r)
    (is_communication(Region{r}) ? comm : compute).insert(std::string(to_string(Region{r})));
  EXPECT_TRUE(compute.count("sor_sweeps"));
  EXPECT_TRUE(compute.count("fft_solve"));
  EXPECT_TRUE(comm.count("transpose_mpi"));
  EXPECT_TRUE(compute.count("mg_solve"));
  EXPECT_TRUE(comm.count("mg_mpi"));
}
