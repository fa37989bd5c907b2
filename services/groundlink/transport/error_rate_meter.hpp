#pragma once
// Receiver-side estimate of the byte error rate p (a byte lost, flipped or inserted) of the link direction
// towards this end, from the frames it hears: a frame of T wire bytes arrives intact with probability
// (1 − p)^T. Frames are kept per size class (powers of two) with good and bad counts, and p is the maximum
// likelihood estimate over all classes, so frames of any mix of sizes (shards of 20 bytes, bulk frames of a
// kilobyte) contribute what they tell. History decays by half every kWindowBytes bytes. The peer reports p to
// the sender, which sizes its frames and switches forward error correction on from it (fec_plan.hpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace airseg::groundlink {

class ErrorRateMeter {
  public:
    static constexpr double kMinBytes = 100.0;       // no estimate below this many bytes
    static constexpr double kMinFrames = 3.0;        // ... or this many frames (early estimates are rough,
                                                     // but a new session needs one within its first command)
    static constexpr double kWindowBytes = 40000.0;  // older history decays by half past this
    static constexpr double kMaxRate = 0.25;         // estimates are capped here
    static constexpr double kBurstRatio = 2.0;  // P(bad | bad before) / P(bad) beyond which errors are bursty
    // Frames vanished per damaged frame heard beyond which errors are bursty, once kMinVanished vanished.
    static constexpr double kVanishedRatio = 0.3;
    static constexpr double kMinVanished = 4.0;

    void on_frame(std::size_t wire_bytes, bool good);
    /// Frames (or shards) that never arrived at all, seen as a gap in their numbering; negative when one
    /// counted so arrives after all. A byte error loses a whole frame only when it hits a delimiter, once
    /// in a frame's length of errors; a lost air packet takes whole frames with it as often as it damages
    /// one.
    void on_vanished(double frames);

    /// The estimated byte error rate, nullopt before enough frames were heard.
    [[nodiscard]] std::optional<double> byte_error_rate() const;
    /// Bad frames come in runs, or whole frames vanish (a lost air packet takes several frames with it),
    /// rather than bytes going bad one by one: parity sized for independent errors would not repair them.
    [[nodiscard]] bool bursty() const;

  private:
    static constexpr std::size_t kClasses = 16;
    struct SizeClass {
        double good = 0.0;
        double bad = 0.0;
        double bytes = 0.0;
    };
    std::array<SizeClass, kClasses> classes_{};
    double bytes_ = 0.0;
    double frames_ = 0.0;
    bool last_bad_ = false;
    double after_bad_ = 0.0;      // frames that followed a bad one
    double bad_after_bad_ = 0.0;  // ... and were bad too
    double vanished_ = 0.0;
    // The estimate is asked for after every input but changes only with a frame: computed once per change
    // (boards without an FPU pay for every exp()).
    mutable bool stale_ = true;
    mutable std::optional<double> estimate_;
    mutable bool bursty_stale_ = true;
    mutable bool bursty_ = false;
    [[nodiscard]] std::optional<double> estimate() const;
    [[nodiscard]] bool judge_bursty() const;
};

}  // namespace airseg::groundlink
