#!/usr/bin/env bash
# End-to-end check of the simulated see-through headset layer on a headless Monado (null
# compositor, simulated HMD): `vitreous run` with the layer and the OpenXR core validation
# layer enabled, once per eye extension, fed with a synthesised visual-effects trace.
# For each case: FOCUSED reached, the frames submitted, the gaze source the case offers, a gaze
# in every recorded frame that is valid exactly when the trace's is and within 0.1 deg of the
# trace interpolated at its time, 0 OpenXR core-validation messages, the blend mode (ADDITIVE,
# or ALPHA_BLEND for `alpha`) used by the app and recorded by the layer for every submitted
# frame (forwarded to Monado as OPAQUE), and a clean runtime exit.
#
# usage: layer/tests/e2e.sh [--frames N] [--keep] [CASE...]
#   CASE                    fb, ext, alpha (FB gaze, `--blend alpha-blend`), ml (default:
#                           fb ext alpha; ml once `vitreous run` reads XR_ML_eye_tracker)
#   VITREOUS_BIN            the vitreous binary (default target/debug/vitreous)
#   VITREOUS_SIM_LAYER_LIB  the layer library (default target/debug/libvitreous_sim_layer.so)
#   VITREOUS_MONADO_PREFIX  provisioned prefix (see tools/monado/provision)
#   VITREOUS_SIM_LAYER_ORDER  XR_ENABLE_API_LAYERS (default: the layer, then core validation)
# Build first: cargo build -p vitreous -p vitreous-sim-layer. Exit status 0 only if every
# case passed; one PASS line per case on stderr.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
frames=100
keep=0
cases=()
while [ $# -gt 0 ]; do
    case $1 in
    --frames)
        frames=$2
        shift
        ;;
    --keep) keep=1 ;;
    -h | --help)
        sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'
        exit 0
        ;;
    fb | ext | ml | alpha) cases+=("$1") ;;
    *)
        echo "sim-layer e2e: unknown argument '$1' (try --help)" >&2
        exit 2
        ;;
    esac
    shift
done
[ ${#cases[@]} -gt 0 ] || cases=(fb ext alpha)

say() { echo "sim-layer e2e: $*" >&2; }
fail() {
    echo "sim-layer e2e: FAIL: $*" >&2
    exit 1
}

bin=${VITREOUS_BIN:-$repo/target/debug/vitreous}
lib=${VITREOUS_SIM_LAYER_LIB:-$repo/target/debug/libvitreous_sim_layer.so}
[ -x "$bin" ] || fail "no vitreous binary at $bin (cargo build -p vitreous)"
[ -f "$lib" ] || fail "no layer library at $lib (cargo build -p vitreous-sim-layer)"

prefix=$("$repo/tools/monado/provision" --quiet) || fail "provisioning Monado failed"
# shellcheck disable=SC1091
source "$prefix/env.sh"
validation_layers=$XR_API_LAYER_PATH

work=$(mktemp -d "${TMPDIR:-/tmp}/vitreous-sim-layer.XXXXXX")
export XDG_RUNTIME_DIR="$work/xdg"
mkdir -m 700 -p "$XDG_RUNTIME_DIR"
service_pid=
cleanup() {
    # Only the service this script started, by its pid.
    if [ -n "$service_pid" ] && kill -0 "$service_pid" 2>/dev/null; then
        kill "$service_pid" 2>/dev/null || true
        wait "$service_pid" 2>/dev/null || true
    fi
    exec 3>&- 2>/dev/null || true
    if [ "$keep" = 1 ]; then
        say "kept $work"
    else
        rm -rf "$work"
    fi
}
trap cleanup EXIT

mkfifo "$work/service.in"
exec 3<>"$work/service.in"
XRT_COMPOSITOR_NULL=1 SIMULATED_ENABLE=1 XRT_LOG=info \
    "${XR_LOADER[@]}" "$prefix/root/usr/bin/monado-service" \
    <"$work/service.in" >"$work/service.log" 2>&1 &
service_pid=$!
for _ in $(seq 150); do
    [ -S "$XDG_RUNTIME_DIR/monado_comp_ipc" ] && break
    kill -0 "$service_pid" 2>/dev/null || {
        tail -20 "$work/service.log" >&2
        fail "monado-service died while starting (log above)"
    }
    sleep 0.2
done
[ -S "$XDG_RUNTIME_DIR/monado_comp_ipc" ] || fail "monado-service did not open its IPC socket in 30 s"

scene="$repo/config/scenes/visual-effects.toml"
"$bin" --log warn trace synth --scene "$scene" --out "$work/gaze.trace" --duration 12 >/dev/null ||
    fail "synthesising the gaze trace failed"

# The layer nearest the app, core validation below it: validation then checks the calls the
# layer makes to the runtime (docs/sim-layer.md explains the order).
layer_order=${VITREOUS_SIM_LAYER_ORDER:-XR_APILAYER_VITREOUS_simulated_ost:XR_APILAYER_LUNARG_core_validation}

# Prints the largest angle, in degrees, between the gaze the app recorded and the synthesised trace's
# gaze interpolated (normalised lerp) at the recorded sample time, with trace time zero at the
# first frame's display time ($3). $1 the trace, $2 the recording, $4 fb (left eye) or ext
# (combined: the trace's own, else the mean of its valid eyes); then the number of recorded frames
# whose gaze validity differs from the trace's nearer sample.
gaze_error_deg() {
    awk -F, -v t0="$3" -v mode="$4" '
        function unit(i) { n = sqrt(x[i] ^ 2 + y[i] ^ 2 + z[i] ^ 2); x[i] /= n; y[i] /= n; z[i] /= n }
        /^#/ || $1 == "time_ns" { next }
        FNR == NR {
            if (m > 0 && t[m] == $9) next
            m++; t[m] = $9; ok[m] = 0
            if (mode == "fb" && $10 == "1") { x[m] = $14; y[m] = $15; z[m] = $16; ok[m] = 1 }
            if (mode == "ext" && $24 != "") { if ($24 == "1") { x[m] = $28; y[m] = $29; z[m] = $30; ok[m] = 1 } }
            else if (mode == "ext" && ($10 == "1" || $17 == "1")) {
                x[m] = ($10 == "1" ? $14 : 0) + ($17 == "1" ? $21 : 0); ok[m] = 1
                y[m] = ($10 == "1" ? $15 : 0) + ($17 == "1" ? $22 : 0)
                z[m] = ($10 == "1" ? $16 : 0) + ($17 == "1" ? $23 : 0)
            }
            if (ok[m]) unit(m)
            next
        }
        {
            tt = $9 - t0; v = (mode == "fb") ? $10 : $24; c = (mode == "fb") ? 14 : 28
            for (i = 1; i < m && t[i + 1] < tt; i++) {}
            # Validity comes from the nearer sample.
            near = (i < m && tt - t[i] >= t[i + 1] - tt) ? i + 1 : i
            if ((v == "1") != (ok[near] == 1)) mismatched++
            if (v != "1" || i >= m || !ok[i] || !ok[i + 1] || tt < t[1]) next
            w = (tt - t[i]) / (t[i + 1] - t[i])
            ax = x[i] + (x[i + 1] - x[i]) * w; ay = y[i] + (y[i + 1] - y[i]) * w; az = z[i] + (z[i + 1] - z[i]) * w
            n = sqrt(ax ^ 2 + ay ^ 2 + az ^ 2)
            d = (ax * $c + ay * $(c + 1) + az * $(c + 2)) / n
            if (d > 1) d = 1
            a = atan2(sqrt(1 - d * d), d) * 180 / 3.14159265358979
            if (a > worst) worst = a
            compared++
        }
        END { if (compared == 0) print "none", mismatched + 0; else printf "%.4f %d\n", worst, mismatched }
    ' "$1" "$2"
}

run_case() {
    local name=$1 gaze=$1 ext_name col blend=additive blend_args=()
    case $name in
    fb) ext_name=XR_FB_eye_tracking_social col=10 ;;
    ext) ext_name=XR_EXT_eye_gaze_interaction col=24 ;;
    ml) ext_name=XR_ML_eye_tracker col=10 ;;
    alpha) gaze=fb ext_name=XR_FB_eye_tracking_social col=10 blend=alpha_blend blend_args=(--blend alpha-blend) ;;
    esac
    local dir="$work/$name"
    mkdir -p "$dir"
    "$repo/tools/sim-layer" --lib "$lib" --gaze "$gaze" "$dir/layers" >/dev/null 2>&1 ||
        fail "$name: tools/sim-layer failed"
    set +e
    XR_API_LAYER_PATH="$dir/layers:$validation_layers" XR_ENABLE_API_LAYERS="$layer_order" \
        VITREOUS_SIM_GAZE=$gaze VITREOUS_SIM_TRACE="$work/gaze.trace" \
        VITREOUS_SIM_SUBMITTED="$dir/submitted.csv" timeout 300 \
        "${XR_LOADER[@]}" "$bin" --log info run "$scene" --frames "$frames" --validate "${blend_args[@]}" \
        --record "$dir/recorded.trace" --out "$dir/run" >"$dir/app.log" 2>&1
    local rc=$?
    set -e
    sed -i 's/\x1b\[[0-9;]*m//g' "$dir/app.log"
    if [ "$rc" != 0 ]; then
        tail -25 "$dir/app.log" >&2
        fail "$name: vitreous run exited with status $rc (log above)"
    fi
    local summary="$dir/run/summary.json"
    [ -f "$summary" ] || fail "$name: no summary.json"
    field() { sed -n "s/^ *\"$1\": \(.*\),\{0,1\}$/\1/p" "$summary" | head -n1 | sed 's/,$//'; }

    if ! grep -q "\"$ext_name\"" "$summary"; then
        [ "$name" = ml ] && {
            say "SKIP $name: vitreous run does not enable $ext_name yet"
            return 0
        }
        fail "$name: the app did not enable $ext_name (extensions: $(grep -A12 '"extensions"' "$summary" | tr -d ' \n'))"
    fi
    [ "$(field reached_focused)" = true ] || fail "$name: the session never reached FOCUSED"
    local submitted
    submitted=$(field frames_submitted)
    [ "$submitted" -ge $((frames * 9 / 10)) ] || fail "$name: only $submitted of $frames frames were submitted"
    local source
    source=$(field gaze_source | tr -d '"')
    case $source in
    *"$ext_name"*) ;;
    *) fail "$name: gaze source is '$source', expected $ext_name" ;;
    esac
    grep -q 'Core Validation Layer is initialized' "$dir/app.log" || fail "$name: the OpenXR core validation layer did not load"
    local xr_messages
    xr_messages=$(grep -c -E 'VALID_ERROR|VALID_WARNING' "$dir/app.log" || true)
    [ "$xr_messages" = 0 ] || {
        grep -E 'VALID_ERROR|VALID_WARNING' "$dir/app.log" | sort | uniq -c | head -5 >&2
        fail "$name: OpenXR core validation reported $xr_messages messages"
    }
    [ "$(field blend | tr -d '"' | tr - _)" = "$blend" ] || fail "$name: the app used blend $(field blend), expected $blend"
    # The layer's record of what the app submitted: a header, then one line per xrEndFrame.
    local lines additive layered
    lines=$(($(wc -l <"$dir/submitted.csv") - 1))
    additive=$(awk -F, -v b="$blend" 'NR > 1 && $3 == b && $7 == "opaque"' "$dir/submitted.csv" | wc -l)
    layered=$(awk -F, 'NR > 1 && $4 >= 1 && $5 ~ /^projection/' "$dir/submitted.csv" | wc -l)
    [ "$additive" = "$lines" ] || fail "$name: $additive of $lines recorded frames were $blend forwarded as opaque"
    [ "$layered" = "$submitted" ] || fail "$name: the layer recorded $layered frames with a projection layer, the app $submitted"
    # Every recorded frame carries a gaze (column $col holds its validity).
    local rows valid
    rows=$(($(wc -l <"$dir/recorded.trace") - 2))
    valid=$(awk -F, -v c="$col" 'NR > 2 && $c == "1"' "$dir/recorded.trace" | wc -l)
    [ "$rows" -ge "$submitted" ] && [ "$valid" -gt 0 ] || fail "$name: $valid of $rows recorded frames have a valid gaze"
    # The gaze values: the trace's, interpolated at the time the layer stamped them.
    local first err mismatched
    first=$(awk -F, 'NR == 2 { print $2 }' "$dir/submitted.csv")
    read -r err mismatched < <(gaze_error_deg "$work/gaze.trace" "$dir/recorded.trace" "$first" "${gaze/ml/fb}")
    [ "$err" != none ] && awk -v e="$err" 'BEGIN { exit !(e < 0.1) }' ||
        fail "$name: the recorded gaze is $err deg from the trace's (more than 0.1 deg)"
    [ "$mismatched" = 0 ] || fail "$name: $mismatched recorded frames differ from the trace in gaze validity"
    say "PASS $name ($ext_name): FOCUSED, $submitted frames, gaze in $rows (valid in $valid as in the trace, \
within $err deg of it), OpenXR validation 0, $lines frames recorded $blend ($layered with a projection layer), forwarded opaque"
}

for c in "${cases[@]}"; do
    run_case "$c"
done

echo quit >&3
for _ in $(seq 100); do
    kill -0 "$service_pid" 2>/dev/null || break
    sleep 0.1
done
kill -0 "$service_pid" 2>/dev/null && fail "monado-service did not exit within 10 s of being asked"
wait "$service_pid" && service_rc=0 || service_rc=$?
service_pid=
[ "$service_rc" = 0 ] || fail "monado-service exited with status $service_rc"
say "all cases passed"
