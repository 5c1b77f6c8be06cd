#include "method_registry.hpp"

#include <cmath>
#include <cstdio>

#include "config_error.hpp"

namespace efsi {

#define EFSI_METHOD(name) const MethodSpec& name##_method();
#include "registered_methods.inc"
#undef EFSI_METHOD

const std::vector<const MethodSpec*>& pressure_methods() {
  static const std::vector<const MethodSpec*> all{
#define EFSI_METHOD(name) &name##_method(),
#include "registered_methods.inc"
#undef EFSI_METHOD
  };
  return all;
}

std::string method_names(const std::string& separator) {
  std::string out;
  for (const MethodSpec* m : pressure_methods()) out += (out.empty() ? "" : separator) + m->name();
  return out;
}

const MethodSpec& find_method(const std::string& name) {
  for (const MethodSpec* m : pressure_methods())
    if (m->name() == name) return *m;
  throw ConfigError("unknown --method '" + name + "': expected one of " + method_names());
}

std::vector<RegisteredOption> registered_options() {
  std::vector<RegisteredOption> out;
  for (const MethodSpec* m : pressure_methods())
    for (const MethodOption& o : m->options()) {
      auto it = out.begin();
      while (it != out.end() && it->option.flag != o.flag) ++it;
      if (it == out.end()) {
        out.push_back({o, {m->name()}});
      } else {  // a flag two methods share: each one's help, in registry order
        it->methods.push_back(m->name());
        if (it->option.help.find(o.help) == std::string::npos) it->option.help += "; " + o.help;
      }
    }
  return out;
}

MethodChoice configure_method(const std::string& name, const OptionValues& given, std::optional<int> nc,
                              bool calibrating) {
  const MethodSpec& spec = find_method(name);
  const std::vector<MethodOption> own = spec.options();
  OptionValues mine;
  for (const auto& [flag, value] : given) {
    const MethodOption* o = nullptr;
    for (const MethodOption& m : own)
      if (m.flag == flag) o = &m;
    if (!o) {
      std::string takers;
      for (const RegisteredOption& r : registered_options())
        if (r.option.flag == flag)
          for (const std::string& t : r.methods) takers += (takers.empty() ? "" : ", ") + t;
      throw ConfigError(flag + " applies to --method " + (takers.empty() ? "none" : takers) + " only");
    }
    if (o->integer && value != std::floor(value))
      throw ConfigError(flag + " " + format_value(value) + " must be a whole number");
    mine[flag] = value;
  }
  if (nc && *nc < 0) throw ConfigError("--nc " + std::to_string(*nc) + " must be 0 (explicit stress) or more");
  MethodChoice choice;
  choice.spec = &spec;
  choice.cn_sweeps = nc.value_or(spec.default_cn_sweeps());
  spec.configure(mine, calibrating, choice);
  return choice;
}

std::string describe_methods() {
  std::string out;
  char b[64];
  for (const MethodSpec* m : pressure_methods()) {
    const ScalingDefaults d = m->scaling_defaults();
    std::snprintf(b, sizeof b, "|%g|%ld|%d|", d.dt, d.steps, m->default_cn_sweeps());
    out += "method " + m->name() + "|" + m->summary() + b + (m->supports(CommMode::async) ? "async" : "sync") + "\n";
    for (const CampaignVariant& v : m->campaign_variants()) {
      std::string args;
      for (const std::string& a : v.args) args += (args.empty() ? "" : " ") + a;
      out += "variant " + m->name() + "|" + v.label + "|" + args + "\n";
    }
  }
  for (const RegisteredOption& r : registered_options()) {
    std::string takers;
    for (const std::string& t : r.methods) takers += (takers.empty() ? "" : ",") + t;
    out += "option " + r.option.flag + "|" + takers + "|" + r.option.help + "\n";
  }
  return out;
}

}  // namespace efsi
