#!/usr/bin/env bash
# Soak: airsegd under full traffic for one simulated hour, watching its memory, file descriptors and CPU.
#
#   bench/soak/soak.sh [--build DIR] [--speedup N] [--sim-seconds S] [--frame-loss P]
#
# The whole bench on ptys: airseg-apmsim at --speedup N (default 30) drives a long boustrophedon scan fed by
# airsegd's rolling window; airseg-linksim is the 57600-baud radio pair with P (default 0.05) of its air
# packets lost; on the ground, airsegctl takes the pushed telemetry (`watch`) and every third round drives a
# joystick burst in MANUAL_NAVIGATION (a FIFO standing in for /dev/input/js0), after which the plan is
# resumed. The radio and
# airsegd run in real time; the vehicle's time runs N times faster, so the autopilot traffic airsegd handles
# is N times that of real driving (a harder load than the real hour).
#
# Every 5 s of real time the script samples airsegd's resident memory (VmRSS), open descriptors and CPU time
# (utime + stime) from /proc. It reports the RSS growth from the end of warm-up (the first 10 % of the run)
# to the end, the descriptor counts, and CPU seconds per simulated second. Exit status 1 when RSS grew by
# 1 MB or more after warm-up, the descriptor count grew, or airsegd died.
set -euo pipefail
cd "$(dirname "$0")/../.."
build=build speedup=30 sim_seconds=3600 frame_loss=0.05
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --speedup) speedup=$2; shift 2 ;;
    --sim-seconds) sim_seconds=$2; shift 2 ;;
    --frame-loss) frame_loss=$2; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "soak: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
for b in daemon/airsegd client/airsegctl tools/apmsim/airseg-apmsim tools/linksim/airseg-linksim; do
  [ -x "$build/$b" ] || { echo "soak: $build/$b is not built (cmake --build $build)" >&2; exit 2; }
done

run=$(pwd)/$build/soak
rm -rf "$run" && mkdir -p "$run"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT INT TERM HUP
wait_for() { for _ in $(seq 200); do [ -e "$1" ] && return 0; sleep 0.1; done; echo "soak: no $1" >&2; exit 1; }
ctl_local() { "$build/client/airsegctl" --local --socket "$run/status.sock" --json --timeout 10000 "$@"; }
ctl_radio() { "$build/client/airsegctl" --link "$run/ground" --timeout 20000 "$@"; }
sim() {  # one command on the simulator's control socket; prints its reply
  python3 - "$run/sim.ctl" "$1" <<'EOF'
import os, socket, sys
server, text = sys.argv[1:]
own = f"{server}.{os.getpid()}"  # the sampler and the traffic loop ask at the same time
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
if os.path.exists(own):
    os.unlink(own)
s.bind(own)
s.settimeout(5)
s.sendto(text.encode(), server)
print(s.recv(65536).decode())
os.unlink(own)
EOF
}

"$build/tools/linksim/airseg-linksim" --a "$run/air" --b "$run/ground" --baud 57600 --frame-loss "$frame_loss" \
  --seed 7 >"$run/linksim.log" 2>&1 &
pids+=($!)
"$build/tools/apmsim/airseg-apmsim" --link "$run/ttyACM0" --control "$run/sim.ctl" --home 41.2752,1.9868 \
  --speedup "$speedup" --mission-capacity 150 --quiet >"$run/apmsim.log" 2>&1 &
pids+=($!)
wait_for "$run/air"
wait_for "$run/ttyACM0"
"$build/daemon/airsegd" --config config/airseg.yaml --set "status.socket=$run/status.sock" \
  --set "state_dir=$run/state" --set "autopilot.port=$run/ttyACM0" --set "groundlink.ports=[$run/air]" \
  --set groundlink.key_file= --set groundlink.insecure=true --set log_level=warn >"$run/airsegd.log" 2>&1 &
daemon=$!
pids+=("$daemon")
for _ in $(seq 300); do
  ctl_local status 2>/dev/null | python3 -c 'import json,sys; sys.exit(0 if json.load(sys.stdin)["autopilot"].get("ready") else 1)' \
    2>/dev/null && break
  sleep 0.2
done

# A scan far longer than the run: 40 lines of 1 km, 6 m apart (about 40 km at 2 m/s: 5.5 simulated hours).
cat >"$run/scan.yaml" <<'EOF'
plan:
  name: soak-scan
  elements:
    - scan: {name: field, rectangle: {sw: [41.2760, 1.9870], ne: [41.2782, 2.0000]}, spacing: 6, step: 20}
EOF
ctl_local plan load "$run/scan.yaml" >/dev/null

mkfifo "$run/js0"
sample() {  # real-seconds rss-kB fds cpu-ticks sim-seconds
  local stat rss fds
  read -r -a stat <"/proc/$daemon/stat"
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$daemon/status")
  fds=$(find "/proc/$daemon/fd" -mindepth 1 -maxdepth 1 | wc -l)
  echo "$SECONDS $rss $fds $((stat[13] + stat[14])) $(sim state | python3 -c 'import json,sys; print(json.load(sys.stdin)["t"])')"
}
(
  while kill -0 "$daemon" 2>/dev/null; do sample; sleep 5; done
) >"$run/samples.txt" &
pids+=($!)

start=$SECONDS
round=0 bursts=0 watch_failures=0
sim_now() { sim state | python3 -c 'import json,sys; print(int(json.load(sys.stdin)["t"]))'; }
sim0=$(sim_now)
while [ $(($(sim_now) - sim0)) -lt "$sim_seconds" ]; do
  kill -0 "$daemon" 2>/dev/null || { echo "soak: airsegd died" >&2; tail -20 "$run/airsegd.log" >&2; exit 1; }
  round=$((round + 1))
  ctl_radio watch --json --duration 20000 >>"$run/watch.jsonl" 2>>"$run/client.log" || watch_failures=$((watch_failures + 1))
  if [ $((round % 3)) -eq 0 ]; then
    # A 3 s joystick burst: forward and a little right, then the device goes away and the plan resumes.
    perl -e 'my @e = (pack("LsCC", 0, -20000, 2, 1), pack("LsCC", 0, 6000, 2, 0));
             $| = 1; for (1..30) { print @e; select(undef, undef, undef, 0.1) }' >"$run/js0" &
    writer=$!
    ctl_radio state MANUAL_NAVIGATION >>"$run/client.log" 2>&1 || true
    ctl_radio joystick --device "$run/js0" --rate 10 >>"$run/client.log" 2>&1 || true
    wait "$writer" 2>/dev/null || true
    ctl_radio plan resume >>"$run/client.log" 2>&1 && bursts=$((bursts + 1))
  fi
done
real=$((SECONDS - start))
sim_total=$(($(sim_now) - sim0))
sleep 6  # one more sample
kill -0 "$daemon" 2>/dev/null || { echo "soak: airsegd died" >&2; exit 1; }
progress=$(ctl_local plan show)

python3 - "$run/samples.txt" "$sim_total" "$real" "$round" "$bursts" "$watch_failures" "$progress" \
  "$(getconf CLK_TCK)" <<'EOF'
import json, sys
path, sim_total, real, rounds, bursts, watch_failures, progress, hz = sys.argv[1:]
rows = [list(map(float, l.split())) for l in open(path) if len(l.split()) == 5]
warm = rows[max(1, len(rows) // 10)]
last = rows[-1]
rss_growth = last[1] - warm[1]
peak = max(r[1] for r in rows)
cpu = (last[3] - rows[0][3]) / float(hz)
sim_span = last[4] - rows[0][4]
p = json.loads(progress)
print(f"soak: {sim_total} simulated s in {real} real s ({rounds} telemetry rounds, {bursts} joystick bursts, "
      f"{watch_failures} watch sessions without a link)")
print(f"soak: plan '{p.get('name')}' state {p.get('state')}, {p.get('waypoints_reached')} waypoints reached, "
      f"{p.get('starvation_holds', 0)} starvation holds")
print(f"soak: airsegd RSS {warm[1]:.0f} kB after warm-up, {last[1]:.0f} kB at the end "
      f"(growth {rss_growth:+.0f} kB, peak {peak:.0f} kB)")
print(f"soak: descriptors {warm[2]:.0f} after warm-up, {last[2]:.0f} at the end")
print(f"soak: CPU {cpu:.1f} s for {sim_span:.0f} simulated s = {1000 * cpu / max(sim_span, 1):.2f} ms per "
      f"simulated second ({100 * cpu / max(last[0] - rows[0][0], 1):.1f} % of one core)")
ok = rss_growth < 1024 and last[2] <= warm[2]
print("soak: " + ("PASS" if ok else "FAIL") + " (RSS growth < 1 MB after warm-up, no descriptor growth)")
sys.exit(0 if ok else 1)
EOF
