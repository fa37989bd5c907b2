#pragma once
// Plan and progress kept in the state directory so that a restarted daemon (even after kill -9) resumes at
// the first unreached waypoint. Every write is atomic: a temp file in the same directory, fsync, rename,
// fsync of the directory. A file that fails its checks (truncated, garbage, written for another plan) is
// reported and set aside as <name>.corrupt-<n>; loading never throws.
//
// Files:
//   plan.yaml       "# airseg-plan v1 fnv64=<hex> bytes=<n> source=<name>" then the plan text verbatim
//                   (still a valid YAML file for a human to read)
//   progress.state  key/value lines ending with "check <fnv64 of the lines before>"
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/fnv1a.hpp"
#include "services/flightplan/feeder_types.hpp"
#include "services/flightplan/waypoint.hpp"

namespace airseg::flightplan {

using airseg::fnv1a64;
std::string hex64(std::uint64_t v);

struct SavedProgress {
    std::string plan_digest;  // hex64(fnv1a64(plan text)) of the plan this progress belongs to
    PlanState state = PlanState::Running;
    StreamOrigin origin;
    std::uint64_t next_index = 0;  // first unreached waypoint
    std::uint64_t waypoints_reached = 0;
    bool operator==(const SavedProgress&) const = default;

    /// From the feeder's progress (nothing to save while there is no resume point or the plan is done).
    static SavedProgress from(const FeederProgress& progress, std::string plan_digest);
};

struct StoredState {
    std::optional<std::string> plan_text;
    std::string plan_source;
    std::optional<SavedProgress> progress;
    std::vector<std::string> problems;  // what was found wrong and set aside
};

enum class Durability : std::uint8_t {
    Fsync,    // survive power loss: fsync the file before the rename and the directory after it
    NoFsync,  // survive a process kill only (simulations, tests)
};

/// Writes `bytes` to `path` atomically. Empty on success, else the error.
std::optional<std::string> write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                                                 Durability durability = Durability::Fsync);

class StateStore {
  public:
    static constexpr std::size_t kMaxPlanBytes = 16u << 20;
    static constexpr std::size_t kMaxPlanFileBytes = kMaxPlanBytes + 512;  // the plan and its header line
    static constexpr std::size_t kMaxProgressBytes = 4096;

    explicit StateStore(std::filesystem::path directory, Durability durability = Durability::Fsync);

    std::optional<std::string> save_plan(std::string_view text, std::string_view source_name);
    std::optional<std::string> save_progress(const SavedProgress& progress);
    /// Forget the plan and its progress (the operator cleared the plan).
    std::optional<std::string> clear();
    /// Reads both files, setting aside whatever is corrupt or does not belong to the stored plan.
    StoredState load();
    /// Sets the plan and its progress aside (a stored plan that passed its checks but cannot be resumed);
    /// what went wrong doing it, if anything.
    std::vector<std::string> set_aside_plan();

    std::filesystem::path plan_path() const { return dir_ / "plan.yaml"; }
    std::filesystem::path progress_path() const { return dir_ / "progress.state"; }

  private:
    std::optional<std::string> set_aside(const std::filesystem::path& path);

    std::filesystem::path dir_;
    Durability durability_;
};

}  // namespace airseg::flightplan
