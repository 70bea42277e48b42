#!/usr/bin/env bash
# Starts gi-server on a free port, runs bench/load/load.mjs in both modes against it and stops it.
#
# usage: bench/load/run.sh [--sessions 8] [--seconds 60] [--size 256x256] [--adaptive]
#                          [--in-flight N] [--cycles 1000] [--settle 3] [--json FILE]
#                          [--server-arg ARG ...]
# The server is $GI_SERVER or build/release/bin/gi-server; --server-arg passes one argument on to it
# (repeat it, e.g. --server-arg --rate-limit --server-arg 400). Exits non-zero when either mode did.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
server="${GI_SERVER:-$root/build/release/bin/gi-server}"

sessions=8 seconds=60 size=256x256 cycles=1000 settle=3 json="" adaptive=() in_flight=() server_args=()
while [[ $# -gt 0 ]]; do
    case "$1" in
        --sessions) sessions="$2"; shift 2 ;;
        --seconds) seconds="$2"; shift 2 ;;
        --size) size="$2"; shift 2 ;;
        --cycles) cycles="$2"; shift 2 ;;
        --settle) settle="$2"; shift 2 ;;
        --json) json="$2"; shift 2 ;;
        --adaptive) adaptive=(--adaptive); shift ;;
        --in-flight) in_flight=(--in-flight "$2"); shift 2 ;;
        --server-arg) server_args+=("$2"); shift 2 ;;
        -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
        *) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
[[ -x "$server" ]] || { echo "run.sh: no gi-server at $server (build it or set GI_SERVER)" >&2; exit 2; }

# A port the kernel just handed out and released: free unless something grabs it in between.
port="$(node -e "const s=require('net').createServer().listen(0,'127.0.0.1',()=>{console.log(s.address().port);s.close()})")"
log="$(mktemp -t gi-load-server.XXXXXX.log)"
max_sessions=$(( sessions > 8 ? sessions : 8 ))
"$server" --host 127.0.0.1 --port "$port" --max-sessions "$max_sessions" "${server_args[@]}" >"$log" 2>&1 &
pid=$!
trap 'kill "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true' EXIT

for _ in $(seq 100); do
    curl -fsS "http://127.0.0.1:$port/healthz" >/dev/null 2>&1 && break
    kill -0 "$pid" 2>/dev/null || { echo "run.sh: gi-server exited; log:" >&2; cat "$log" >&2; exit 1; }
    sleep 0.1
done

token=()
for ((i = 0; i < ${#server_args[@]}; ++i)); do
    [[ "${server_args[$i]}" == --token ]] && token=(--token "${server_args[$((i + 1))]}")
done
common=(--url "ws://127.0.0.1:$port/ws" --size "$size" --pid "$pid" "${token[@]}" "${in_flight[@]}")
[[ -n "$json" ]] && common+=(--json "$json")

status=0
echo "== sessions: $sessions x $seconds s, $size (server log: $log)"
node "$here/load.mjs" "${common[@]}" --sessions "$sessions" --seconds "$seconds" "${adaptive[@]}" || status=1
echo "== cycles: $cycles"
node "$here/load.mjs" "${common[@]}" --cycles "$cycles" --settle "$settle" || status=1
exit "$status"
