#pragma once
// Batched halo exchange: every field of the batch travels in one message per neighbour
// direction, as the paper sends all quantities together.
//
// Reach::full talks to all 26 neighbours (faces, edges, corners) at once, so every ghost,
// corners included, is filled in a single round of independent messages; that is what
// lets the async form overlap the whole exchange with interior work (a dimension-by-
// dimension exchange would serialise x, y and z).  Reach::full_phased fills the same ghosts
// with bitwise the same values by three rounds of face messages, x, then y, then z, each
// round carrying the ghosts the rounds before it filled: 6 messages instead of 26, fewer
// and longer, at the price of rounds that wait for each other (what a network with a high
// cost per message, or a simulator that models every flow, prefers).  Reach::faces talks
// to the 6 face neighbours only, for star stencils (the 7-point Laplacian) that never read
// corners.
//
// Periodic wrap in x and z comes from the Cartesian communicator; a rank that is its own
// neighbour copies locally without MPI; across the walls in y the ghosts are mirrored by
// each field's WallParity (odd: the field vanishes on the wall face and changes sign in
// the ghosts; even: extended evenly).
#include <mpi.h>

#include <array>
#include <cstddef>
#include <vector>

#include "decomposition.hpp"
#include "field.hpp"
#include "region_timers.hpp"
#include "storage.hpp"

namespace efsi {

enum class Reach { faces, full, full_phased };

// How a full exchange reaches the edge and corner ghosts (--halo): by their own messages,
// or through the faces in three rounds.
enum class HaloPattern { direct, phased };
inline const char* to_string(HaloPattern p) { return p == HaloPattern::direct ? "direct" : "phased"; }
inline Reach full_reach(HaloPattern p) { return p == HaloPattern::direct ? Reach::full : Reach::full_phased; }

class HaloExchange {
 public:
  // Fields must outlive the exchange and share the decomposition; buffers and copy
  // lists are built here once and reused every call.
  // `axes`: the axes exchanged.  A direction that steps along a left-out axis is skipped,
  // and its ghosts are left as they are, but for the wall face rows of an odd y-face field,
  // which the wall rule zeroes whole; leaving out y leaves the walls alone too.
  HaloExchange(const CartDecomposition& decomp, std::vector<Field*> fields, Reach reach = Reach::full,
               RegionTimers* timers = nullptr, std::array<bool, 3> axes = {true, true, true});
  HaloExchange(const HaloExchange&) = delete;
  HaloExchange& operator=(const HaloExchange&) = delete;

  // Sync form: pack, one blocking MPI_Sendrecv per direction, unpack, walls.
  void exchange();
  // Async form: begin() packs and posts non-blocking sends and receives; the caller
  // may then compute on anything but the ghosts; finish() waits, unpacks, applies walls.
  // Both forms leave bitwise the same ghosts. Ghosts whose neighbour is this rank itself
  // (a periodic wrap, no message) are already current when begin() returns, so work next
  // to such faces need not wait for finish() (the SOR's async interior uses this).
  void begin();
  // Between begin() and finish(): lets MPI move the messages on (MPI_Testall). Without it a
  // large message (rendezvous protocol) waits for finish() to start, and nothing overlaps.
  // The simulation build tests only a phased round that is not the last.
  void progress();
  void finish();
  // Between begin() and finish(): waits for the messages that cross the faces of `axis`
  // and fills those ghosts: direct, the faces, and the edges and corners with a step along
  // it; phased, the rounds up to that axis's, so the face ghosts over the owned rows of the
  // later axes (the edges and corners wait for the later rounds).  The walls and the other
  // directions wait for finish().  With the ghosts beyond both x faces current, a stage
  // can take whole rows before the rest arrives.
  void finish_across(int axis);

  // Whether the ghosts beyond the face on `side` (-1 or +1) of `axis` are current when
  // begin() returns: the face's neighbour is this rank itself (not another, not a wall),
  // and, phased, its round is the first.
  bool face_current_at_begin(int axis, int side) const {
    return peer_[kSelf + side * (axis == 0 ? 1 : axis == 1 ? 3 : 9)] == self_ && round_of_axis_[axis] <= 0;
  }
  // Phased: the round (0, 1, 2) that carries the faces of `axis`, packed only when the
  // rounds before it are done; -1 where every message is packed by begin().
  int round_of_axis(int axis) const { return round_of_axis_[axis]; }
  std::size_t bytes_sent_mpi() const { return mpi_doubles_ * sizeof(double); }  // per call, this rank
  int rounds() const { return rounds_; }  // rounds of messages that wait for each other
  std::size_t bytes_copied_local() const { return local_doubles_ * sizeof(double); }
  int messages_sent() const { return mpi_messages_; }
  const std::vector<Field*>& fields() const { return fields_; }

 private:
  static constexpr int kDirs = 27;  // index (sx+1) + 3 (sy+1) + 9 (sz+1)
  static constexpr int kSelf = 13;  // (0, 0, 0): the rank itself
  static constexpr int kMaxRounds = 3;
  struct Run {  // `rows` x-runs of `len` points, `stride` apart (one y-column of a box at fixed k)
    int dir;  // the neighbour direction
    int field;
    int len;
    int rows;
    std::ptrdiff_t index, stride;
    std::size_t buf;  // the runs lie back to back in the buffer from here
  };
  struct SelfRun {  // `rows` x-runs of `len` points copied within one field, owned -> ghost
    int field;
    int len;
    int rows;
    std::ptrdiff_t src, dst, stride;
  };
  struct WallRun {  // dst = sign * src over len points (sign 0: set to zero)
    int field;
    std::ptrdiff_t dst, src;
    int len;
    double sign;
  };

  void build_runs(const CartDecomposition& decomp);
  void build_walls(const CartDecomposition& decomp);
  // The remote directions' points of round r into the send buffer.
  void pack(int r);
  // The ghosts of round r whose neighbour is this rank, straight from its own points.
  void copy_self(int r);
  // The remote directions' ghosts of round r from the receive buffer, then (walls) the walls.
  void unpack(int r, bool walls);
  // Posts round r: receives, pack, self-copies, sends.
  void start_round(int r);
  // Waits for the round in flight, unpacks it (the last one with the walls) and posts the next.
  void complete_round();

  std::vector<Field*> fields_;
  Reach reach_;
  std::array<bool, 3> axes_;
  RegionTimers* timers_;
  int self_ = 0;
  MPI_Comm comm_ = MPI_COMM_NULL;
  int peer_[kDirs];
  std::size_t send_off_[kDirs]{}, send_count_[kDirs]{}, recv_off_[kDirs]{}, recv_count_[kDirs]{};
  int rounds_ = 1;
  int round_of_dir_[kDirs]{};
  int round_of_axis_[3] = {-1, -1, -1};  // phased: each exchanged axis's round; -1 otherwise
  std::vector<Run> send_runs_[kMaxRounds], recv_runs_[kMaxRounds];  // remote directions only
  std::vector<SelfRun> self_runs_[kMaxRounds];
  std::size_t round_mpi_doubles_[kMaxRounds]{}, round_local_doubles_[kMaxRounds]{};
  std::vector<WallRun> wall_zero_, wall_mirror_;
  Storage send_buf_, recv_buf_;
  std::vector<MPI_Request> requests_;
  int recv_request_[kDirs];       // index in requests_ of the receive from each direction, or -1
  int finished_across_ = -1;      // direct: the axis finish_across already unpacked, or -1
  int round_ = 0;                 // the round in flight (rounds_: all complete)
  std::size_t mpi_doubles_ = 0, local_doubles_ = 0;
  std::size_t across_doubles_[3]{};  // received across the faces of each axis (finish_across)
  std::size_t wall_doubles_ = 0;     // set by the wall rule
  int mpi_messages_ = 0;
  bool in_flight_ = false;
};

}  // namespace efsi
