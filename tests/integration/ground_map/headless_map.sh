# shellcheck shell=bash
# Sourced by browser_test.sh and moments_test.sh (set `fixture`, airseg-map-fixture's path, first): the
# headless browser, the fixture serving the map, and a work directory that goes with the test however the test
# ends (the fixtures it started are stopped then too).

browser=${CHROMIUM:-$(command -v chromium || command -v chromium-browser || true)}
if [ -z "$browser" ]; then
  echo "FAIL: chromium is not installed; install it with: sudo apt-get install chromium libjs-leaflet" >&2
  exit 1
fi
if [ ! -f /usr/share/javascript/leaflet/leaflet.js ]; then
  echo "FAIL: Leaflet is not installed; install it with: sudo apt-get install libjs-leaflet" >&2
  exit 1
fi

work=$(mktemp -d)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

# Starts the fixture with options "$@"; sets $url, $fixture_pid and $fixture_out (its output).
launch_fixture() {
  fixture_out=$work/fixture.$RANDOM
  "$fixture" "$@" >"$fixture_out" 2>&1 &
  fixture_pid=$!
  pids+=("$fixture_pid")
  for _ in $(seq 100); do
    url=$(sed -n 's/^listening on \(http:[^ ]*\)$/\1/p' "$fixture_out")
    [ -n "$url" ] && return 0
    sleep 0.1
  done
  echo "FAIL: airseg-map-fixture did not start:" >&2
  cat "$fixture_out" >&2
  exit 1
}

# The page at --url in headless chromium once --until holds (headless_page.py: options "$@"); on a profile of
# its own, its messages to $work/browser.log. Each step has a deadline and a failing one is named.
capture_page() {
  python3 "$(dirname "${BASH_SOURCE[0]}")/headless_page.py" --browser "$browser" \
    --profile "$work/profile.$RANDOM" --log "$work/browser.log" "$@"
}
