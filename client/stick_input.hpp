#pragma once
// Operator stick input for airsegctl joystick: a Linux joystick device (/dev/input/js*, the js_event API) or
// the keyboard. The decoders are sans-IO (bytes in, stick position out); StickSource owns the file
// descriptor and, for a terminal, its raw mode.
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace airseg::client {

struct Stick {
    double steering = 0;  // -1 full left .. 1 full right
    double throttle = 0;  // -1 full reverse .. 1 full forward
    bool quit = false;    // the operator asked to stop
};

/// Decodes js_event records (8 bytes each: time u32, value s16, type u8, number u8, in the host's byte
/// order, as the kernel writes them). Axis 0 steers; axis 1 is throttle, pushed forward = negative values.
class JsEventDecoder {
  public:
    void feed(std::span<const std::uint8_t> bytes);
    [[nodiscard]] const Stick& stick() const { return stick_; }

  private:
    std::array<std::uint8_t, 8> partial_{};
    std::size_t have_ = 0;
    Stick stick_;
};

/// Keyboard driving: w/s or Up/Down change throttle, a/d or Left/Right steering, by `step` per key; space
/// centres both; q quits.
class KeyboardDecoder {
  public:
    explicit KeyboardDecoder(double step = 0.1) : step_(step) {}
    void feed(std::span<const std::uint8_t> bytes);
    [[nodiscard]] const Stick& stick() const { return stick_; }

  private:
    double step_;
    int escape_ = 0;  // 0 none, 1 after ESC, 2 after ESC [
    Stick stick_;
};

/// Reads whatever input is ready without blocking.
class StickSource {
  public:
    /// `device` empty: the keyboard on stdin (raw mode when it is a terminal). Returns nullptr and sets
    /// `error` when the device cannot be opened.
    static std::unique_ptr<StickSource> open(const std::string& device, std::string& error);
    ~StickSource();
    StickSource(const StickSource&) = delete;
    StickSource& operator=(const StickSource&) = delete;

    /// Takes pending input; false once the device is gone (end of file, unplugged).
    bool poll();
    [[nodiscard]] Stick stick() const;
    [[nodiscard]] bool keyboard() const { return keyboard_; }

  private:
    StickSource() = default;
    int fd_ = -1;
    bool owns_fd_ = false;
    bool keyboard_ = false;
    bool restore_terminal_ = false;
    std::string saved_terminal_;  // `stty -g` of the terminal before raw mode
    JsEventDecoder js_;
    KeyboardDecoder keys_;
};

}  // namespace airseg::client
