#!/usr/bin/env bash
# What the rbdem command line tells a new user, end to end on tiny scenes (about 30 s):
#   1. sweep and calibrate refuse a likely unit mistake (a strength at or above its modulus) in any case before
#      running one, naming the case and the key; sweep --force runs it
#   2. a scene given twice, and --beta / --spacing / geometry --set together with --mesh, are refused (exit 2)
#   3. an unknown command or option names the one meant; a study where a scene belongs (and the converse) says
#      which command reads it
#   4. the help and the printed scene name the built-in paper scene (Scene.ShippedPaperSceneEqualsBuiltInDefaults
#      keeps it equal to scenes/paper.toml)
#   5. a run estimated to need more memory than the machine has is refused before meshing; a long one prints the
#      estimate
#   6. not on a terminal, progress comes as plain lines with the time left
#   7. a run lists the files it wrote
#   8. figures use $RBDEM_PYTHON; the figure script says in one line what is missing instead of a traceback
# Usage: cli_guidance.sh RBDEM
set -euo pipefail
rbdem=$1
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cd "$work"
tiny=(--set specimen.width=0.01 --set specimen.height=0.02 --set joint_set.spacing=0.006 --set mesh.size=0.002
      --set numerics.threads=1 --skip-elastic-gate)
fail() { echo "FAIL: $1"; [ -f "${2:-}" ] && cat "$2"; exit 1; }
# expect_refusal LOG TEXT...: the last command exited 2 and its output holds every TEXT
expect_refusal() {
  local rc=$1 log=$2; shift 2
  [ "$rc" -eq 2 ] || fail "expected exit 2, got $rc" "$log"
  for text in "$@"; do grep -qF -- "$text" "$log" || fail "the message lacks '$text'" "$log"; done
}
run() { set +e; timeout 60 "$rbdem" "$@" > out.log 2>&1; rc=$?; set -e; }

cat > tiny.toml <<'EOF'
[specimen]
width = 0.01
height = 0.02
[joint_set]
spacing = 0.006
[mesh]
size = 0.002
EOF
# A study whose second case has a cohesion of 200 GPa (a unit mistake) and stops at a small strain when forced.
cat > bad_study.toml <<'EOF'
[study]
name = "bad"
base = "tiny.toml"
dips = [60]
[study.set]
"loading.max_strain" = 2e-4
"numerics.threads" = 1
[[axis]]
name = "rock_cohesion"
labels = ["ok", "huge"]
[axis.set]
"rock.cohesion" = [7.51e6, 200e9]
EOF
cat > bad_calibration.toml <<'EOF'
[calibrate]
base = "tiny.toml"
max_iterations = 1
dips = [90]
[[parameter]]
name = "rock_strength"
keys = ["rock.cohesion"]
ratios = [1.0]
start = 200e9
min = 1e6
max = 1e12
[[target]]
quantity = "strength"
beta = 90
value = 50e6
EOF

# 1. Unit mistakes in a study or a calibration: refused before any case runs, by case and key.
run sweep bad_study.toml --out sweep_bad --skip-elastic-gate
expect_refusal "$rc" out.log "rock_cohesion=huge/beta=60" "rock.cohesion" "--force"
[ ! -d sweep_bad/rock_cohesion=ok ] || fail "sweep ran a case before refusing"
run calibrate bad_calibration.toml --out cal_bad
expect_refusal "$rc" out.log "rock.cohesion" "start"
[ ! -d cal_bad/eval_00 ] || fail "calibrate ran an evaluation before refusing"
echo "OK: sweep and calibrate refuse a strength above its modulus before running"

# 2. Options that would be ignored.
run ucs tiny.toml --scene tiny.toml -q --out twice
expect_refusal "$rc" out.log "give the scene once"
"$rbdem" mesh -q "${tiny[@]:0:8}" --out tiny.msh > /dev/null
for option in "--beta 30" "--spacing 0.004" "--set joint_set.dip_deg=30" "--set mesh.size=0.001" \
              "--set specimen.width=0.02"; do
  # shellcheck disable=SC2086
  run ucs -q --mesh tiny.msh $option --skip-elastic-gate --out meshed
  expect_refusal "$rc" out.log "${option%% *}" "the mesh file fixes"
done
"$rbdem" mesh -q --mesh tiny.msh --set specimen.thickness=0.5 > /dev/null || fail "specimen.thickness with --mesh refused"
echo "OK: a scene given twice and geometry options with --mesh are refused"

# 3. Mistyped commands and options, files for the wrong command.
run ucss
expect_refusal "$rc" out.log "unknown command 'ucss'" "did you mean 'ucs'?" "sweep" "calibrate"
run xyzzy
expect_refusal "$rc" out.log "unknown command 'xyzzy'"
! grep -q "did you mean" out.log || fail "a suggestion for a word far from every command" out.log
run ucs --bta 60
expect_refusal "$rc" out.log "--bta" "did you mean --beta?"
run ucs bad_study.toml
expect_refusal "$rc" out.log "is a study" "rbdem sweep bad_study.toml"
run bad_study.toml
expect_refusal "$rc" out.log "rbdem sweep bad_study.toml"
run sweep tiny.toml
expect_refusal "$rc" out.log "is a scene" "rbdem ucs tiny.toml"
run ucs bad_calibration.toml
expect_refusal "$rc" out.log "rbdem calibrate bad_calibration.toml"
echo "OK: unknown commands and options, and files given to the wrong command"

# 4. The built-in scene, named as such.
builtin="the built-in paper scene (the same values as scenes/paper.toml)"
"$rbdem" --help | tr -s ' \n' ' ' | grep -qF "$builtin" || fail "rbdem --help does not say '$builtin'"
"$rbdem" mesh "${tiny[@]:0:8}" > out.log
grep -qF "# resolved scene from $builtin" out.log || fail "the printed scene does not say '$builtin'" out.log
echo "OK: the built-in paper scene is named in the help and the printed scene"

# 5. The cost estimate: refused beyond the available memory, printed for a long run.
run ucs -q --set mesh.size=1e-5 --skip-elastic-gate --out huge
expect_refusal "$rc" out.log "mesh.size = 1e-05 m" "of memory" "MemAvailable" "use mesh.size >="
run ucs "${tiny[@]}" --set loading.platen_velocity=1e-7 --interrupt-at-step 10 --out slow
[ "$rc" -eq 130 ] || fail "expected exit 130 from --interrupt-at-step, got $rc" out.log
grep -E "estimate before meshing: about [0-9]+ blocks, [0-9]+ bonds, [0-9]+ MB of memory, [0-9.]+ (min|h|days) per run" \
  out.log > /dev/null || fail "no cost estimate for a long run" out.log
echo "OK: $(grep -o 'estimate before meshing.*' out.log)"

# 6 and 7. Progress as plain lines off a terminal; the files written.
"$rbdem" ucs "${tiny[@]}" --set loading.platen_velocity=0.0002 --progress-seconds 0 --out progress > out.log < /dev/null
grep -E "^  step [0-9]+, strain [0-9.e+-]+, stress [0-9.-]+ MPa \(peak [0-9.]+ MPa\), [0-9]+ cracks, .* elapsed, left " \
  out.log > /dev/null || fail "no plain progress lines off a terminal" out.log
listed=$(sed -n 's/^ucs: wrote into progress: //p' out.log | tr -d ' ' | tr ',' '\n' | sort)
present=$(ls progress | sort)
[ -n "$listed" ] && [ "$listed" = "$present" ] || fail "the files listed ($listed) are not those in the folder ($present)" out.log
echo "OK: progress lines off a terminal; wrote $(echo $listed)"

# 8. Figures with $RBDEM_PYTHON (a wrapper that logs its calls), and the figure script without matplotlib.
system_python=/usr/bin/python3
if "$system_python" -c "import matplotlib, h5py, numpy" 2> /dev/null; then
  printf '#!/bin/sh\necho "$@" >> %s/python_calls.log\nexec %s "$@"\n' "$work" "$system_python" > mypython
  chmod +x mypython
  RBDEM_PYTHON=$work/mypython timeout 120 "$rbdem" sweep bad_study.toml --force --skip-elastic-gate --out sweep_forced \
    > out.log 2>&1 < /dev/null || fail "sweep --force did not run the study" out.log
  grep -q "sweep: case rock_cohesion=huge/beta=60 done" out.log || fail "no line per finished case off a terminal" out.log
  [ -s python_calls.log ] || fail "the figures did not use \$RBDEM_PYTHON" out.log
  ls sweep_forced/*.png > /dev/null 2>&1 || fail "no figures with \$RBDEM_PYTHON" sweep_forced/report.md
  echo "OK: sweep --force runs the study; figures made with \$RBDEM_PYTHON"
else
  echo "note: $system_python lacks matplotlib, h5py or numpy; the \$RBDEM_PYTHON case is skipped"
fi
mkdir -p fake/matplotlib
echo 'raise ModuleNotFoundError("No module named matplotlib", name="matplotlib")' > fake/matplotlib/__init__.py
set +e; PYTHONPATH=$work/fake "$system_python" "$here/../python/rbdem_figures.py" --help > out.log 2>&1; rc=$?; set -e
expect_refusal "$rc" out.log "matplotlib" "apt-get install python3-matplotlib python3-h5py python3-numpy"
! grep -q Traceback out.log || fail "a traceback instead of one line" out.log
[ "$(wc -l < out.log)" -eq 1 ] || fail "more than one line" out.log
echo "OK: the figure script names the missing module in one line, exit 2"
