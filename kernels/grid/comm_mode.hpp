#pragma once
// How a step's halo exchanges meet its computation (docs/architecture.md, "one step"):
// sync exchanges complete before the work that reads the ghosts; async posts them and does
// the work that reads no ghost while they travel.  Both give bitwise the same fields.
namespace efsi {

enum class CommMode { sync, async };

inline const char* to_string(CommMode m) { return m == CommMode::sync ? "sync" : "async"; }

}  // namespace efsi
