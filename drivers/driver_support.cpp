#include "driver_support.hpp"

#include <mpi.h>

#include <cstdio>
#include <memory>
#include <sstream>

#include "config_error.hpp"
#include "output_error.hpp"
#include "runtime.hpp"
#include "stepper.hpp"
#include "text_file.hpp"

namespace efsi {
namespace {

constexpr std::size_t kHelpWidth = 100;  // --help lines fit a terminal and a code review

// Each paragraph of `text` broken at spaces into lines of at most `width` characters.
std::string wrap(const std::string& text, std::size_t width) {
  std::string out, line, word;
  std::istringstream paragraphs(text);
  std::string paragraph;
  bool first = true;
  while (std::getline(paragraphs, paragraph)) {
    if (!first) out += '\n';
    first = false;
    std::istringstream words(paragraph);
    line.clear();
    while (words >> word) {
      if (!line.empty() && line.size() + 1 + word.size() > width) {
        out += line + '\n';
        line.clear();
      }
      line += (line.empty() ? "" : " ") + word;
    }
    out += line;
  }
  return out;
}

// CLI11 2.1 leaves long descriptions on one line; this one wraps them, option help beside
// the option column.
class WrappingFormatter final : public CLI::Formatter {
 public:
  std::string make_option_desc(const CLI::Option* opt) const override {
    return wrap(CLI::Formatter::make_option_desc(opt), kHelpWidth - get_column_width());
  }
  std::string make_description(const CLI::App* app) const override {
    return wrap(CLI::Formatter::make_description(app), kHelpWidth) + "\n";
  }
  std::string make_footer(const CLI::App* app) const override {
    const std::string footer = CLI::Formatter::make_footer(app);
    return footer.empty() ? footer : wrap(footer, kHelpWidth) + "\n";
  }
};

template <class T, class Parse>
std::array<T, 3> parse3(const std::string& text, const std::string& option, Parse parse) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) parts.push_back(item);
  if (parts.size() != 1 && parts.size() != 3)
    throw ConfigError(option + " '" + text + "': expected one value or three separated by commas");
  std::array<T, 3> out{};
  for (int a = 0; a < 3; ++a) {
    const std::string& p = parts[parts.size() == 1 ? 0 : a];
    try {
      std::size_t used = 0;
      out[a] = parse(p, &used);
      if (used != p.size()) throw std::invalid_argument(p);
    } catch (const std::exception&) {
      throw ConfigError(option + " '" + text + "': '" + p + "' is not a number");
    }
  }
  return out;
}

}  // namespace

Int3 parse_int3(const std::string& text, const std::string& option) {
  const Int3 v = parse3<int>(text, option, [](const std::string& s, std::size_t* u) { return std::stoi(s, u); });
  for (int a = 0; a < 3; ++a)
    if (v[a] < 1) throw ConfigError(option + " '" + text + "': " + std::to_string(v[a]) + " must be at least 1");
  return v;
}

std::array<double, 3> parse_double3(const std::string& text, const std::string& option) {
  return parse3<double>(text, option, [](const std::string& s, std::size_t* u) { return std::stod(s, u); });
}

void add_force_memory_flag(CLI::App& app, bool& force_memory) {
  app.add_flag("--force-memory", force_memory, "run even when the memory estimate exceeds what the node has available");
}

bool is_root() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r == 0;
}

int run_driver(int argc, char** argv, CLI::App& app, const std::function<int()>& body) {
  Runtime runtime(argc, argv);
  const std::string name = app.get_name();
  app.formatter(std::make_shared<WrappingFormatter>());
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    if (runtime.rank() == 0) std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::Success&) {  // an option that answered and ends the run (--list-methods)
    return 0;
  } catch (const CLI::ParseError& e) {
    if (runtime.rank() == 0) std::fprintf(stderr, "%s: error: %s (see --help)\n", name.c_str(), e.what());
    return 2;
  }
  try {
    return body();
  } catch (const ConfigError& e) {
    if (runtime.rank() == 0) std::fprintf(stderr, "%s: error: %s\n", name.c_str(), e.what());
    return 2;
  } catch (const OutputError& e) {
    if (runtime.rank() == 0) std::fprintf(stderr, "%s: error: %s\n", name.c_str(), e.what());
    return 5;
  } catch (const BlowUp& e) {
    if (runtime.rank() == 0) std::fprintf(stderr, "%s: %s; nothing recorded as valid\n", name.c_str(), e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error on rank %d: %s\n", name.c_str(), runtime.rank(), e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
    return 1;
  }
}

}  // namespace efsi
