#include "step_exchanges.hpp"

namespace efsi {

std::vector<Field*> step_exchange_fields(StepExchange x, FsiState& state, FsiWork& work) {
  switch (x) {
    case StepExchange::state: return state.all();
    case StepExchange::vstar: return {&work.vstar[0], &work.vstar[1], &work.vstar[2]};
    case StepExchange::divergence: return {&work.div};
    case StepExchange::count: break;
  }
  return {};
}

}  // namespace efsi
