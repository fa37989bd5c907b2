#pragma once
// Loopback ports for the programs a test starts (airsegd, airseg-ground, airsegctl, a broker take port
// numbers on their command line), reserved so that no other test process on the machine gets the same one.
//
// A port "free at the moment of asking" (bind port 0, close, return the number) is not reserved: the kernel
// hands the same ephemeral port to the next process that binds port 0 or connects, and two suites on one
// machine (CI's sanitizer suite beside a developer's, two ARM suites) then race for it. Here each port comes
// from a range below the kernel's ephemeral range (which the kernel never hands out by itself), and is held
// by an flock() on a lock file per port (AIRSEG_TEST_PORT_DIR, default /tmp/airseg-test-ports) until the test
// process ends: the kernel drops the lock when the process dies, however it dies.

#include <string>

namespace airseg::test {

/// A loopback port (127.0.0.1) that no other test process on this machine is given while this process
/// lives, and that was free for both UDP and TCP when it was reserved. Throws when the range is exhausted.
int reserve_loopback_port();

/// The same, for a program that binds UDP or TCP; both names stay for the tests that use them.
inline int free_udp_port() {
    return reserve_loopback_port();
}
inline int free_tcp_port() {
    return reserve_loopback_port();
}

/// The lock file whose flock() holds `port` (for the tests of the reservation itself).
std::string port_lock_path(int port);

}  // namespace airseg::test
