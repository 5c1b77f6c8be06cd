#pragma once
// The halo exchanges of one step, in one table: what each carries and which stage needs
// its ghosts (docs/architecture.md, "one step").  The pressure methods and Crank-Nicolson
// own further exchanges of their own fields (dp; v* and tau*), named where they are built.
#include <array>
#include <vector>

#include "fsi_equations.hpp"
#include "halo_exchange.hpp"

namespace efsi {

enum class StepExchange : int { state, vstar, divergence, count };

struct StepExchangeSpec {
  StepExchange id;
  const char* name;
  const char* carries;
  Reach reach;
  const char* needed_by;
};

inline constexpr std::array<StepExchangeSpec, static_cast<int>(StepExchange::count)> kStepExchanges{{
    {StepExchange::state, "state", "u, v, w, p, phi, Bt (6)", Reach::full,
     "stress, momentum and transport tendencies (points next to the block's faces, edges, corners)"},
    {StepExchange::vstar, "v*", "u*, v*, w*", Reach::faces, "divergence D* (and Crank-Nicolson's first sweep)"},
    {StepExchange::divergence, "D*", "D*", Reach::faces, "pressure increment (the Laplacian of D*)"},
}};

// The fields an exchange of the table carries, in the order of `carries`.
std::vector<Field*> step_exchange_fields(StepExchange x, FsiState& state, FsiWork& work);

}  // namespace efsi
