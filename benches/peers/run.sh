#!/usr/bin/env bash
# kanegen vs its peers on the same URDFs, in one run: kanegen's generated Rust (dynamics!),
# CasADi-generated C (Pinocchio's algorithms traced on casadi::SX) and numeric Pinocchio (C++),
# for M(q), c(q, v), (M, c), inverse and forward dynamics, their derivatives and M⁻¹. Everything
# from scratch: venv, pip install, random chains, model export, SX tracing, C codegen, gcc / g++,
# cargo (one crate build per model, timed), validation against numeric Pinocchio, interleaved
# timing, report.
# Not part of .ci/run. See benches/peers/README.md.
#
#   bash benches/peers/run.sh              # from the project root; results in target/peers/out/
#
# Knobs (environment variables, all optional):
#   PASSES=5          timing passes; each pass times every (side, label, model, function)
#   ROUNDS=15         timed rounds per function and pass (the pass reports their median)
#   CALLS=20000       at most this many calls per round (cycling over the 20 states) ...
#   ROUND_US=4000     ... fewer for slow functions, so that a round lasts about ROUND_US µs
#   MODELS="name=path.urdf ..."   the fixed models (default: SSRMS, SRMS, UR5, xArm7, Panda)
#   RANDOM_N="2 4 8 16 32 64"     random chains (tools/random_chain.py); "" for none
#   RANDOM_SEED=20260101
#   NATIVE=1          also build and time kanegen with RUSTFLAGS="-C target-cpu=native", with its
#                     fma = true variant (own target dir)
#   BUILD_TIMEOUT=1200  seconds per kanegen crate build (one model); a build over it is recorded
#                     as "timeout" and the model's kanegen rows stay empty
#   CC_TIMEOUT=1200   seconds per gcc compile of one generated C file (same treatment)
#   CHECK_SPLIT=1     also time `cargo check` of each default build (expansion + type check,
#                     no LLVM), to split the compile time
#   CASADI_EXTRA=""   more CasADi variants to generate, compile and time: plain, simp
#   WORLD=1           CasADi and Pinocchio also in Convention::WORLD (M_world, aba_world)
#   DERIVS=1          the derivative rows (rnea_derivs, aba_derivs, minv; CasADi also rnea_jac,
#                     aba_jac) on all three sides; the kanegen side needs a dynamics! that emits
#                     inverse_dynamics_derivatives, forward_dynamics_derivatives and
#                     mass_matrix_inverse. DERIVS=peers: CasADi and Pinocchio only; DERIVS=0: none
#   KANEGEN_C=1       the "kanegen C" side: `kanegen generate --lang c` behind CasADi's entry points
#                     (src/kanegen_c), compiled with the same $CC $COPT as CasADi's C and timed by the
#                     same driver; 0: none
#   CASADI_SIDE=1     0: no CasADi side (no tracing, no gcc of generated C): Pinocchio and kanegen
#                     only, e.g. for the run-time path against numeric Pinocchio
#   TIMING_ONLY=0     1: reuse everything an earlier complete run built in PEERS_WORK (models,
#                     binaries, compile times) and redo only validation, timing and report
#   KANEGEN_DIR       the kanegen checkout (default: the project this script is in); for a copy
#                     without .git (e.g. `git archive HEAD`), KANEGEN_REV names its commit
#                     in versions.txt
#   PEERS_WORK        venv, builds, results (default: KANEGEN_DIR/target/peers)
#   KANEGEN_TARGET_DIR / KANEGEN_NATIVE_TARGET_DIR  cargo target dirs (default: PEERS_WORK/build/target[-native])
#   CC=gcc CXX=g++ COPT="-O3 -march=native"   C/C++ compilers and flags (no -ffast-math)
#   PIN_CPU           CPU for taskset (default: the last CPU; none if taskset is missing)
#   PYTHON=python3    interpreter used to create the venv
set -euo pipefail
SRC_DIR=$(cd "$(dirname "$0")" && pwd)
KANEGEN_DIR=$(cd "${KANEGEN_DIR:-$SRC_DIR/../..}" && pwd)
[ -f "$KANEGEN_DIR/Cargo.toml" ] || { echo "KANEGEN_DIR=$KANEGEN_DIR is not a kanegen checkout" >&2; exit 1; }
WORK=${PEERS_WORK:-$KANEGEN_DIR/target/peers}
mkdir -p "$WORK"
WORK=$(cd "$WORK" && pwd)
rm -rf "$WORK/src" "$WORK/tools" "$WORK/kanegen_bench_src"
cp -rp "$SRC_DIR/src" "$SRC_DIR/tools" "$SRC_DIR/requirements.txt" "$WORK/"
cp -rp "$SRC_DIR/kanegen_bench" "$WORK/kanegen_bench_src"
chmod -R u+w "$WORK"
cd "$WORK"

PASSES=${PASSES:-5}
ROUNDS=${ROUNDS:-15}
CALLS=${CALLS:-20000}
ROUND_US=${ROUND_US:-4000}
NATIVE=${NATIVE:-1}
BUILD_TIMEOUT=${BUILD_TIMEOUT:-1200}
CC_TIMEOUT=${CC_TIMEOUT:-1200}
CHECK_SPLIT=${CHECK_SPLIT:-1}
TIMING_ONLY=${TIMING_ONLY:-0}
CASADI_EXTRA=${CASADI_EXTRA:-}
WORLD=${WORLD:-1}
DERIVS=${DERIVS:-1}
case $DERIVS in
  0) PEERS_DERIVS=0; KG_FEATURES="" ;;
  peers) PEERS_DERIVS=1; KG_FEATURES="" ;;
  1) PEERS_DERIVS=1; KG_FEATURES="--features derivs" ;;
  *) echo "DERIVS=$DERIVS: 1, peers or 0" >&2; exit 1 ;;
esac
export PEERS_DERIVS
CASADI_SIDE=${CASADI_SIDE:-1}
KANEGEN_C=${KANEGEN_C:-1}
CC=${CC:-gcc}
CXX=${CXX:-g++}
COPT=${COPT:-"-O3 -march=native"}
PY=${PYTHON:-python3}
RANDOM_N=${RANDOM_N-"2 4 8 16 32 64"}
RANDOM_SEED=${RANDOM_SEED:-20260101}
REF=$KANEGEN_DIR/tests/data/reference
ERD=$KANEGEN_DIR/tests/data/erd
MODELS=${MODELS-"ssrms=$REF/ssrms_nguyen_hughes_1994.urdf srms=$REF/srms_nguyen_hughes_1994.urdf ur5=$ERD/ur5_robot.urdf xarm7=$ERD/xarm7.urdf panda=$ERD/panda.urdf"}
KTD=${KANEGEN_TARGET_DIR:-$WORK/build/target}
KTD_NATIVE=${KANEGEN_NATIVE_TARGET_DIR:-$WORK/build/target-native}

COMPILE=out/compile_times.csv
if [ "$TIMING_ONLY" = 1 ]; then
  [ -f build/models/models.json ] && [ -x .venv/bin/python ] && [ -f $COMPILE ] ||
    { echo "TIMING_ONLY=1 needs a complete earlier run in $WORK" >&2; exit 1; }
  cp $COMPILE build/compile_times.prev.csv
  rm -rf out; mkdir -p out/dumps logs
  cp build/compile_times.prev.csv $COMPILE
  LOG=logs/run-timing-only.log
else
  rm -rf out logs
  mkdir -p build out/dumps logs
  echo "side,build,model,step,seconds,status" > $COMPILE
  LOG=logs/run.log
fi
exec > >(tee "$LOG") 2>&1
T_START=$SECONDS
stamp() { echo "== [$((SECONDS - T_START)) s] $*"; }
now() { date +%s.%N; }
since() { echo "$(now) $1" | awk '{printf "%.2f", $1 - $2}'; }
stamp "kanegen peer bench, $(date -u +%Y-%m-%dT%H:%M:%SZ); kanegen $KANEGEN_DIR; work $WORK"

declare -A SNAP CLABELS KBUILT
if [ "$TIMING_ONLY" = 1 ]; then
  VPY=$WORK/.venv/bin/python
  NAMES=$($VPY -c "import json; print(' '.join(json.load(open('build/models/models.json'))))")
  PIN_LABELS=""
  [ -x build/pin_numeric_hdr ] && PIN_LABELS=hdr
  for m in $NAMES; do
    CLABELS[$m]=""
    for d in build/c/"$m"/*/; do [ -x "$d/driver" ] && CLABELS[$m]="${CLABELS[$m]} $(basename "$d")"; done
  done
  KKINDS="default clean"
  if ls build/bin/kanegen_native_* > /dev/null 2>&1; then KKINDS="$KKINDS native"; fi
  for k in $KKINDS; do for m in $NAMES; do [ -x "build/bin/kanegen_${k}_$m" ] && KBUILT[$k.$m]=1; done; done
  stamp "TIMING_ONLY=1: reusing the models, binaries and compile times in $WORK"
else
# ------------------------------------------------------------------ 1. venv
t0=$(now)
if [ ! -x .venv/bin/python ]; then "$PY" -m venv .venv; fi
VPY=$WORK/.venv/bin/python
$VPY -m pip install -q --disable-pip-version-check -r requirements.txt
SITE=$($VPY -c 'import os, sysconfig; print(os.path.relpath(sysconfig.get_paths()["purelib"]))')
PREFIX=$WORK/$SITE/cmeel.prefix
CASADI=$WORK/$SITE/casadi
for f in "$PREFIX/include/pinocchio/autodiff/casadi.hpp" "$PREFIX/include/eigen3/Eigen/Core" \
         "$CASADI/include/casadi/casadi.hpp" "$CASADI/libcasadi.so"; do
  [ -e "$f" ] || { echo "not found after pip install: $f" >&2; exit 1; }
done
stamp "venv ready in $(since "$t0") s"

# ------------------------------------------------------------------ 2. models, states, reference
stamp "models (tools/random_chain.py, tools/prepare.py)"
rm -rf build/models build/random
ALL_MODELS=$MODELS
if [ -n "$RANDOM_N" ]; then
  # shellcheck disable=SC2086
  $VPY tools/random_chain.py $RANDOM_N --seed "$RANDOM_SEED" --out build/random > /dev/null
  for n in $RANDOM_N; do ALL_MODELS="$ALL_MODELS random_n$n=$WORK/build/random/random_n$n.urdf"; done
fi
# shellcheck disable=SC2086
$VPY tools/prepare.py --out build/models $ALL_MODELS | sed 's/^/   /'
NAMES=$(for m in $ALL_MODELS; do echo "${m%%=*}"; done)
snapped() { $VPY -c "import json,sys; print(json.load(open('build/models/models.json'))[sys.argv[1]]['snapped'])" "$1"; }
for m in $NAMES; do SNAP[$m]=$(snapped "$m"); done

# ------------------------------------------------------------------ 3. C++ programs
CXXDEF="-DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12"
cached_build() {  # cached_build OUT SRC CMD: rebuild when the command or the sources changed
  local out=$1 src=$2 cmd=$3
  if [ -x "$out" ] && [ "$(cat "$out.cmd" 2>/dev/null)" = "$cmd" ] && [ "$out" -nt "$src" ] &&
     [ "$out" -nt src/model_txt.hpp ] && [ "$out" -nt src/timing.h ]; then
    stamp "$out is up to date (built in $(cat "$out.sec" 2>/dev/null || echo '?') s by an earlier run)"
    echo "cxx,$(basename "$out"),all,compile,$(cat "$out.sec" 2>/dev/null || echo 0),ok-cached" >> $COMPILE; return 0
  fi
  stamp "compiling $out"
  local t0; t0=$(now)
  if eval "$cmd" > "logs/$(basename "$out").log" 2>&1; then
    echo "$cmd" > "$out.cmd"; since "$t0" > "$out.sec"; echo "   built in $(since "$t0") s"
    echo "cxx,$(basename "$out"),all,compile,$(since "$t0"),ok" >> $COMPILE
  else
    echo "   FAILED (logs/$(basename "$out").log)"; tail -5 "logs/$(basename "$out").log"
    echo "cxx,$(basename "$out"),all,compile,$(since "$t0"),error" >> $COMPILE; return 1
  fi
}
GEN_CMD="$CXX -std=c++17 -O1 -DNDEBUG -w $CXXDEF -DCASADI_SNPRINTF=snprintf -DCASADI_WITH_THREADSAFE_SYMBOLICS -DCASADI_WITH_THREAD -I$PREFIX/include -I$PREFIX/include/eigen3 -I$CASADI/include src/pin_casadi_gen.cpp -o build/pin_casadi_gen -L$CASADI -lcasadi -ldl -Wl,-rpath,$CASADI"
[ "$CASADI_SIDE" = 1 ] && cached_build build/pin_casadi_gen src/pin_casadi_gen.cpp "$GEN_CMD"
PIN_HDR_CMD="$CXX -std=c++17 $COPT -DNDEBUG -w $CXXDEF -I$PREFIX/include -I$PREFIX/include/eigen3 src/pin_numeric.cpp -o build/pin_numeric_hdr"
cached_build build/pin_numeric_hdr src/pin_numeric.cpp "$PIN_HDR_CMD"
PIN_LABELS="hdr"

# ------------------------------------------------------------------ 4. Pinocchio<SX> -> CasADi -> C
if [ "$CASADI_SIDE" != 1 ]; then
  stamp "CASADI_SIDE=$CASADI_SIDE: no CasADi side"
  for m in $NAMES; do CLABELS[$m]=""; done
else
stamp "tracing + CasADi codegen (variants: cse${CASADI_EXTRA:+ $CASADI_EXTRA}; cse_clean where the clean model differs)"
rm -rf gen
for m in $NAMES; do
  t0=$(now)
  # shellcheck disable=SC2086
  PEERS_WORLD=$WORLD build/pin_casadi_gen "build/models/$m.model.txt" "gen/$m" cse $CASADI_EXTRA > "logs/gen_$m.log" 2>&1
  echo "casadi,cse,$m,trace+codegen,$(since "$t0"),ok" >> $COMPILE
  if [ "${SNAP[$m]}" != 0 ]; then
    t0=$(now)
    PEERS_WORLD=$WORLD build/pin_casadi_gen "build/models/$m.clean.model.txt" "gen/$m" cse_clean >> "logs/gen_$m.log" 2>&1
    echo "casadi,cse_clean,$m,trace+codegen,$(since "$t0"),ok" >> $COMPILE
  fi
  printf '   %-11s %s; %s lines of C (cse)\n' "$m" "$(grep -h " cse M_nle:" "logs/gen_$m.log" | head -n1 | sed 's/.*M_nle: //')" \
    "$(wc -l < "gen/$m/cse/casadi_gen.c")"
done

# ------------------------------------------------------------------ 5. C drivers
# label -> generated variant and extra flags; gcc's default for GNU C is -ffp-contract=fast,
# so -march=native (FMA) lets it fuse a*b+c; cse_nocontract turns that off.
stamp "compiling the C drivers ($CC $COPT; timeout $CC_TIMEOUT s per generated file; objects cached by content in build/cc-cache)"
mkdir -p build/cc-cache
CC_VERSION=$($CC --version | head -n1)
variant_of() { case $1 in cse_nocontract) echo cse ;; *) echo "$1" ;; esac; }
flags_of() { case $1 in cse_nocontract) echo "$COPT -ffp-contract=off" ;; *) echo "$COPT" ;; esac; }
labels_of() {  # the CasADi labels of one model
  local l="cse cse_nocontract"
  [ "${SNAP[$1]}" != 0 ] && l="$l cse_clean"
  echo "$l $CASADI_EXTRA"
}
for m in $NAMES; do
  CLABELS[$m]=""
  for lab in $(labels_of "$m"); do
    v=$(variant_of "$lab"); fl=$(flags_of "$lab"); d=build/c/$m/$lab
    mkdir -p "$d"
    # the generated file is deterministic: reuse an object compiled from the same text and flags
    key=$( { cat "gen/$m/$v/casadi_gen.c"; echo "$CC_VERSION | $fl"; } | sha256sum | cut -c1-40)
    t0=$(now)
    if [ -f "build/cc-cache/$key.o" ] && [ -f "build/cc-cache/$key.sec" ]; then
      cp "build/cc-cache/$key.o" "$d/casadi_gen.o"; tc=$(cat "build/cc-cache/$key.sec"); cst=ok-cached
    else
      rc=0
      # shellcheck disable=SC2086
      timeout -k 10 "$CC_TIMEOUT" $CC $fl -c "gen/$m/$v/casadi_gen.c" -o "$d/casadi_gen.o" 2> "logs/cc_${m}_$lab.log" || rc=$?
      if [ $rc = 0 ]; then
        tc=$(since "$t0"); cst=ok
        cp "$d/casadi_gen.o" "build/cc-cache/$key.o"; echo "$tc" > "build/cc-cache/$key.sec"
      else
        cst=failed; st=$([ $rc = 124 ] || [ $rc = 137 ] && echo timeout || echo error)
      fi
    fi
    if [ "$cst" != failed ]; then
      # shellcheck disable=SC2086
      $CC $fl -std=c11 -Wall -DPEERS_WORLD=$WORLD -DPEERS_DERIVS=$PEERS_DERIVS -I"gen/$m/$v" -Isrc -c src/driver.c -o "$d/driver.o"
      $CC "$d/driver.o" "$d/casadi_gen.o" -lm -o "$d/driver"
      echo "casadi,$lab,$m,cc,$tc,$cst" >> $COMPILE
      CLABELS[$m]="${CLABELS[$m]} $lab"
      printf '   %-11s %-15s %8s s  (%s)%s\n' "$m" "$lab" "$tc" "$fl" "$([ $cst = ok ] || echo ' object reused; time of the run that compiled it')"
    else
      echo "casadi,$lab,$m,cc,$(since "$t0"),$st" >> $COMPILE
      printf '   %-11s %-15s %s after %s s (logs/cc_%s_%s.log)\n' "$m" "$lab" "$st" "$(since "$t0")" "$m" "$lab"
    fi
  done
done

fi  # CASADI_SIDE

# ------------------------------------------------------------------ 6. kanegen bench crate
# One crate build per model and build kind, so that a build's wall time is that of one
# dynamics! (expansion + rustc of the emitted code), dependencies already compiled.
KB=build/kanegen_bench
rm -rf "$KB/src" "$KB/models"; mkdir -p "$KB/src" "$KB/models" build/bin
cp kanegen_bench_src/main.rs "$KB/src/"
for m in $NAMES; do cp "build/models/$m.urdf" "build/models/$m.clean.toml" "$KB/models/"; done
[ -e "$KB/Cargo.lock" ] || cp "$KANEGEN_DIR/Cargo.lock" "$KB/" 2>/dev/null || true
cat > "$KB/Cargo.toml" <<EOF
[package]
name = "kanegen_peer_bench"
version = "0.0.0"
edition = "2021"
publish = false

[dependencies]
kanegen = { path = "$KANEGEN_DIR", default-features = false }
# the run-time path (aba_runtime): the model read from its URDF, the kernel ABA
kanegen-dynamics = { path = "$KANEGEN_DIR/dynamics" }
kanegen-model = { path = "$KANEGEN_DIR/model" }

[features]
# the derivative rows (DERIVS=1): the model's type has inverse_dynamics_derivatives,
# forward_dynamics_derivatives and mass_matrix_inverse
derivs = []

[workspace]
EOF
cargo_env() {  # cargo_env TARGET_DIR RUSTFLAGS CMD...
  local td=$1 rf=$2; shift 2
  if [ -n "$rf" ]; then (cd "$KB" && RUSTFLAGS="$rf" CARGO_TARGET_DIR="$td" timeout -k 10 "$BUILD_TIMEOUT" "$@")
  else (cd "$KB" && env -u RUSTFLAGS CARGO_TARGET_DIR="$td" timeout -k 10 "$BUILD_TIMEOUT" "$@"); fi
}
use_source() {  # use_source MODEL KIND: src/kanegen_models.rs for one build
  cp "build/models/$1.states.rs" "$KB/src/"
  cp "build/models/$1.kg_$2.rs" "$KB/src/kanegen_models.rs"
  touch "$KB/src/kanegen_models.rs"
}
kbuild() {  # kbuild KIND TARGET_DIR RUSTFLAGS: deps once, then one timed build per model
  local kind=$1 td=$2 rf=$3 first t0 st rc
  mkdir -p "$td"
  stamp "kanegen builds '$kind' (RUSTFLAGS='$rf', CARGO_TARGET_DIR=$td, timeout $BUILD_TIMEOUT s per model)"
  # dependencies (and the first, smallest model, discarded): not part of any model's time
  first=$(for m in $NAMES; do echo "$($VPY -c "import json; print(json.load(open('build/models/models.json'))['$m']['n'])") $m"; done | sort -n | head -n1 | cut -d' ' -f2)
  use_source "$first" default
  t0=$(now)
  if cargo_env "$td" "$rf" cargo build --release -q $KG_FEATURES > "logs/kanegen_${kind}_deps.log" 2>&1; then
    echo "kanegen,$kind,deps,build,$(since "$t0"),ok" >> $COMPILE
    echo "   dependencies (kanegen, kanegen-macros and the generator crates) in $(since "$t0") s"
  else
    echo "kanegen,$kind,deps,build,$(since "$t0"),error" >> $COMPILE
    echo "   dependency build FAILED (logs/kanegen_${kind}_deps.log)"; tail -20 "logs/kanegen_${kind}_deps.log"; return 0
  fi
  for m in $NAMES; do
    local src=$kind
    [ "$kind" = native ] || [ "$kind" = default ] || [ "${SNAP[$m]}" != 0 ] || continue  # clean only where it differs
    if [ "$kind" = default ] && [ "$CHECK_SPLIT" = 1 ]; then
      use_source "$m" "$src"
      t0=$(now)
      if cargo_env "$td" "$rf" cargo check --release -q $KG_FEATURES > "logs/kanegen_${kind}_${m}_check.log" 2>&1; then st=ok; else rc=$?; st=$([ $rc = 124 ] || [ $rc = 137 ] && echo timeout || echo error); fi
      echo "kanegen,$kind,$m,check,$(since "$t0"),$st" >> $COMPILE
    fi
    use_source "$m" "$src"
    t0=$(now)
    if cargo_env "$td" "$rf" cargo build --release -q $KG_FEATURES > "logs/kanegen_${kind}_$m.log" 2>&1; then
      st=ok
      cp "$td/release/kanegen_peer_bench" "build/bin/kanegen_${kind}_$m"
      KBUILT[$kind.$m]=1
    else
      rc=$?; st=$([ $rc = 124 ] || [ $rc = 137 ] && echo timeout || echo error)
    fi
    echo "kanegen,$kind,$m,build,$(since "$t0"),$st" >> $COMPILE
    printf '   %-11s %-8s %8s s  %s\n' "$m" "$kind" "$(since "$t0")" "$st$([ "$st" = ok ] || echo " (logs/kanegen_${kind}_$m.log)")"
  done
}
KKINDS="default clean"
kbuild default "$KTD" ""
kbuild clean "$KTD" ""
if [ "$NATIVE" = 1 ]; then
  kbuild native "$KTD_NATIVE" "-C target-cpu=native"
  KKINDS="$KKINDS native"
fi
fi  # TIMING_ONLY
label_of_kind() { case $1 in clean) echo default ;; *) echo "$1" ;; esac; }

# ------------------------------------------------------------------ 6b. kanegen's C output
# The same functions as C (`kanegen generate --lang c`: the same plan and graphs, printed as
# C99), behind CasADi's entry points (src/kanegen_c), compiled as CasADi's C is (the same $CC
# and $COPT, alone, no LTO) and timed by the same driver: generator against generator under one
# compiler. Built in every mode (TIMING_ONLY too): it takes seconds.
KCMODELS=""
if [ "$KANEGEN_C" = 1 ]; then
  stamp "kanegen C: kanegen generate --lang c, then $CC $COPT"
  rm -rf build/kc
  KG_BIN=${CARGO_TARGET_DIR:-$KANEGEN_DIR/target}/release/kanegen
  if (cd "$KANEGEN_DIR" && cargo build --release -q --bin kanegen) > logs/kanegen_bin.log 2>&1; then
    for m in $NAMES; do
      d=build/kc/$m
      mkdir -p "$d"
      t0=$(now)
      if ! "$KG_BIN" generate "build/models/$m.urdf" --name Kg --ignore-mimic --no-derivatives --lang c \
          -o "$d/kg.h" > "logs/kc_generate_$m.log" 2>&1; then
        echo "kanegen,c,$m,generate,$(since "$t0"),error" >> $COMPILE
        printf '   %-11s generate failed (logs/kc_generate_%s.log)\n' "$m" "$m"
        continue
      fi
      echo "kanegen,c,$m,generate,$(since "$t0"),ok" >> $COMPILE
      t0=$(now); rc=0
      # shellcheck disable=SC2086
      timeout -k 10 "$CC_TIMEOUT" $CC $COPT -I"$d" -Isrc/kanegen_c -c src/kanegen_c/kanegen_c.c \
        -o "$d/kanegen_c.o" 2> "logs/cc_${m}_kanegen_c.log" || rc=$?
      if [ $rc = 0 ]; then
        tc=$(since "$t0")
        # shellcheck disable=SC2086
        $CC $COPT -std=c11 -Wall -DPEERS_WORLD=0 -DPEERS_DERIVS=0 -DPEERS_SIDE='"kanegen"' \
          -Isrc/kanegen_c -Isrc -c src/driver.c -o "$d/driver.o"
        $CC "$d/driver.o" "$d/kanegen_c.o" -lm -o "$d/driver"
        echo "kanegen,c,$m,cc,$tc,ok" >> $COMPILE
        KCMODELS="$KCMODELS $m"
        printf '   %-11s %8s s  (%s)\n' "$m" "$tc" "$COPT"
      else
        st=$([ $rc = 124 ] || [ $rc = 137 ] && echo timeout || echo error)
        echo "kanegen,c,$m,cc,$(since "$t0"),$st" >> $COMPILE
        printf '   %-11s %s after %s s (logs/cc_%s_kanegen_c.log)\n' "$m" "$st" "$(since "$t0")" "$m"
      fi
    done
  else
    echo "   the kanegen binary did not build (logs/kanegen_bin.log): no kanegen C side"
  fi
fi
has_kc() { [[ " $KCMODELS " == *" $1 "* ]]; }

# ------------------------------------------------------------------ 7. validation
stamp "validation against Pinocchio numeric (Python), gravity 0"
rm -f out/dumps/*.json
for m in $NAMES; do
  for lab in ${CLABELS[$m]}; do
    "build/c/$m/$lab/driver" "build/models/$m.states.txt" "$lab" "$m" dump > "out/dumps/casadi.$m.$lab.json"
  done
  for pl in $PIN_LABELS; do
    "build/pin_numeric_$pl" "build/models/$m.model.txt" "build/models/$m.states.txt" "$pl" "$m" dump > "out/dumps/pinocchio.$m.$pl.json"
  done
  if has_kc "$m"; then
    "build/kc/$m/driver" "build/models/$m.states.txt" c "$m" dump > "out/dumps/kanegen_c.$m.json"
  fi
  for k in $KKINDS; do
    [ -n "${KBUILT[$k.$m]:-}" ] || continue
    "build/bin/kanegen_${k}_$m" "$(label_of_kind "$k")" dump > "out/dumps/kanegen.$k.$m.json"
  done
done
VALID=ok
$VPY tools/validate.py build/models out/dumps --rtol 1e-9 > out/validation.txt || VALID=failed
grep -E "FAIL|validation" out/validation.txt || true

# ------------------------------------------------------------------ 8. versions
PIN=""
if command -v taskset >/dev/null && [ "$(nproc)" -gt 1 ]; then PIN="taskset -c ${PIN_CPU:-$(( $(nproc) - 1 ))}"; fi
{
  echo "date (UTC): $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "cpu: $(lscpu | sed -n 's/^Model name: *//p' | head -n1) (family $(lscpu | sed -n 's/^CPU family: *//p') model $(lscpu | sed -n 's/^Model: *//p'); $CC -march=native = $($CC -march=native -Q --help=target 2>/dev/null | sed -n 's/^ *-march=[[:space:]]*//p' | head -n1)); $(nproc) CPUs; $(lscpu | sed -n 's/^Hypervisor vendor: *//p'); $(grep -o -w 'avx512f\|avx2\|fma' /proc/cpuinfo | sort -u | tr '\n' ' ')"
  echo "memory: $(free -g | awk '/^Mem:/ {print $2 " GiB"}'); load average at timing start: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "kernel: $(uname -sr)"
  echo "python: $($VPY --version 2>&1); packages: $($VPY -m pip list --disable-pip-version-check 2>/dev/null | grep -Ei '^(pin|libpinocchio|casadi|cmeel-eigen|cmeel-boost|numpy) ' | awk '{printf "%s %s; ", $1, $2}')"
  echo "C/C++: $($CC --version | head -n1); $($CXX --version | head -n1); flags $COPT (cse_nocontract: + -ffp-contract=off); CasADi C compiled separately from its driver (no LTO); numeric Pinocchio header-only (label hdr)"
  echo "rust: $(rustc --version); cargo $(cargo --version | cut -d' ' -f2); release profile defaults (opt-level 3, codegen-units 16, no LTO; proc-macros at build-override opt-level 0)"
  if git -C "$KANEGEN_DIR" rev-parse --git-dir > /dev/null 2>&1; then
    echo "kanegen: $KANEGEN_DIR @ $(git -C "$KANEGEN_DIR" rev-parse --short HEAD)$(git -C "$KANEGEN_DIR" diff --quiet HEAD -- 2>/dev/null || echo ' (uncommitted changes)')"
  else
    echo "kanegen: $KANEGEN_DIR (not a git checkout${KANEGEN_REV:+; KANEGEN_REV=$KANEGEN_REV})"
  fi
  echo "timing: PASSES=$PASSES ROUNDS=$ROUNDS CALLS<=$CALLS ROUND_US=$ROUND_US; pinned: ${PIN:-none}"
  echo "timeouts: BUILD_TIMEOUT=$BUILD_TIMEOUT s per kanegen crate build, CC_TIMEOUT=$CC_TIMEOUT s per generated C file"
} > out/versions.txt

# ------------------------------------------------------------------ 9. timing, interleaved
echo "pass,side,label,model,func,median_ns,min_ns,calls,checksum,wall_median_ns" > out/times.csv
run_casadi() {
  for m in $NAMES; do for lab in ${CLABELS[$m]}; do
    $PIN "build/c/$m/$lab/driver" "build/models/$m.states.txt" "$lab" "$m" time "$ROUNDS" "$CALLS" "$ROUND_US" | sed "s/^/$1,/" >> out/times.csv
  done
  # kanegen's C beside CasADi's, by the same driver
  if has_kc "$m"; then
    $PIN "build/kc/$m/driver" "build/models/$m.states.txt" c "$m" time "$ROUNDS" "$CALLS" "$ROUND_US" | sed "s/^/$1,/" >> out/times.csv
  fi
  done
}
run_pinocchio() {
  for m in $NAMES; do for pl in $PIN_LABELS; do
    $PIN "build/pin_numeric_$pl" "build/models/$m.model.txt" "build/models/$m.states.txt" "$pl" "$m" time "$ROUNDS" "$CALLS" "$ROUND_US" | sed "s/^/$1,/" >> out/times.csv
  done; done
}
run_kanegen() {
  for m in $NAMES; do for k in $KKINDS; do
    [ -n "${KBUILT[$k.$m]:-}" ] || continue
    $PIN "build/bin/kanegen_${k}_$m" "$(label_of_kind "$k")" time "$ROUNDS" "$CALLS" "$ROUND_US" | sed "s/^/$1,/" >> out/times.csv
  done; done
}
SIDES=(casadi pinocchio kanegen)
for pass in $(seq 1 "$PASSES"); do
  order=()
  for i in 0 1 2; do order+=("${SIDES[$(( (i + pass - 1) % 3 ))]}"); done
  stamp "timing pass $pass/$PASSES (${PIN:-no pinning}; order ${order[*]})"
  for s in "${order[@]}"; do "run_$s" "$pass"; done
done

# ------------------------------------------------------------------ 10. report
stamp "report (out/results.md, out/results.json)"
TOTAL=$((SECONDS - T_START))
$VPY tools/report.py --out out --gen gen --models build/models/models.json --total-seconds "$TOTAL" \
  $([ "$TIMING_ONLY" = 1 ] && echo --timing-only) > /dev/null
stamp "done in $TOTAL s; validation: $VALID; results: $WORK/out/results.md"
