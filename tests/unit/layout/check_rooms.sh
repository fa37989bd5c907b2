#!/usr/bin/env bash
# Each line of code knows its room: only hal/ touches termios and libgpiod, only daemon/ talks to systemd,
# nothing outside services/autopilot/ (and the tools that speak to an autopilot) knows MAVLink, and the lower
# rooms (base/ at the bottom, hal/ above it) know nothing of the rooms above them.
set -euo pipefail
root=${1:?source dir}
cd "$root"
fail=0
report() {
  local what=$1 hits=$2
  if [ -n "$hits" ]; then
    echo "FAIL: $what outside its room:"
    echo "$hits" | sed 's/^/  /'
    fail=1
  else
    echo "ok: $what"
  fi
}
check() {
  local what=$1 pattern=$2 allowed=$3
  report "$what" "$(grep -rlE "$pattern" --include='*.cpp' --include='*.hpp' --include='*.h' \
                      daemon services hal groundside client tools 2>/dev/null | grep -vE "$allowed" || true)"
}
check "termios/ioctl serial headers" '#include <(termios\.h|asm/termbits\.h|sys/ioctl\.h|pty\.h)>' '^hal/'
check "libgpiod" '#include <gpiod\.h>' '^hal/'
check "systemd notify protocol" '(#include <systemd/sd-daemon\.h>|sd_notify\(|NOTIFY_SOCKET)' '^daemon/'
check "MAVLink outside the autopilot layer" '#include "services/autopilot/mavlink/' '^(services/autopilot/|tools/(mavdump|apmsim)/)'
# groundlink and the flight plan service speak only the autopilot-neutral vocabulary (airseg_autopilot_api):
# no ArduPilot driver or MAVLink header, and no library that brings them in.
report "ArduPilot/MAVLink headers (included by groundlink or flightplan)" \
  "$(grep -rlE '#include "services/autopilot/(ardupilot|mavlink)/' --include='*.cpp' --include='*.hpp' \
       --include='*.h' services/groundlink services/flightplan || true)"
report "the ArduPilot driver or MAVLink library (linked by groundlink or flightplan)" \
  "$(grep -lE 'airseg_mavlink|airseg_autopilot([^_[:alnum:]]|$)' services/groundlink/CMakeLists.txt \
       services/flightplan/CMakeLists.txt || true)"
# hal/ sits below the services and the programs; it may use base/ and itself only.
report "services/, daemon/, groundside/ or client/ headers (included by hal)" \
  "$(grep -rlE '#include "(services|daemon|groundside|client)/' --include='*.cpp' --include='*.hpp' --include='*.h' \
       hal || true)"
# groundside/ is the ground-side code airsegctl (client/) and airseg-ground (ground/) share: it includes
# neither program's code, and neither program includes the other's.
report "client/ or ground/ headers (included by groundside)" \
  "$(grep -rlE '#include "(client|ground)/' --include='*.cpp' --include='*.hpp' --include='*.h' groundside || true)"
report "the other program's headers (client/ included by ground, ground/ by client)" \
  "$({ grep -rl '#include "client/' --include='*.cpp' --include='*.hpp' --include='*.h' ground
       grep -rl '#include "ground/' --include='*.cpp' --include='*.hpp' --include='*.h' client; } || true)"
# base/ is the bottom room: every other room may include it, so it includes none of them.
report "headers of other rooms (included by base)" \
  "$(grep -rn '#include "' --include='*.cpp' --include='*.hpp' --include='*.h' base | grep -v '#include "base/' ||
       true)"
# A service sees another only through the top-level headers of its directory (its bus vocabulary and
# interface); the subdirectories (groundlink's transport/, link/, protocol/, the autopilot's ardupilot/,
# mavlink/) are that service's internals.
internals=""
for dir in services/*/; do
  own=$(basename "$dir")
  internals+=$(grep -rlE "#include \"services/[a-z_]+/[a-z_]+/" --include='*.cpp' --include='*.hpp' --include='*.h' \
                 "$dir" | while read -r f; do
                   grep -oE "#include \"services/[a-z_]+/[a-z_]+/" "$f" | grep -vq "services/$own/" && echo "$f"
                 done || true)
done
report "another service's internals (a subdirectory of services/OTHER/)" "$internals"
# The status LED's meanings belong to the daemon's services, the blinking to hal/ (it names no daemon state).
report "daemon meanings in hal (Booting/Ready/LinkUp/Fault patterns)" \
  "$(grep -rlE 'LedPattern|Booting|LinkUp' --include='*.cpp' --include='*.hpp' hal || true)"
exit $fail
