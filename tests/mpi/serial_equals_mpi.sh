#!/usr/bin/env bash
# ctest Mpi.SerialEqualsTwoRanks: every distributed command prints, under `mpirun -n 2`, exactly what it prints in
# one process (byte for byte), and a failing case ends every rank. Skips (77) only when rollsim was built without MPI.
# Usage: serial_equals_mpi.sh ROLLSIM DISTRIBUTE_CHECK SOURCE_DIR SHARED_DIR MPIEXEC WITH_MPI
set -uo pipefail
rollsim=$1 check=$2 src=$3 shared=$4 mpiexec=$5 with_mpi=$6
if [ "$with_mpi" != "ON" ] && [ "$with_mpi" != "1" ] && [ "$with_mpi" != "TRUE" ]; then
  echo "SKIP: rollsim was built without MPI (ROLLSIM_WITH_MPI=$with_mpi; Debian: libopenmpi-dev openmpi-bin)"
  exit 77
fi
mpirun=("$mpiexec" -n 2 --oversubscribe)
[ "$(id -u)" -eq 0 ] && mpirun+=(--allow-run-as-root)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$src" || exit 1
head -101 "$shared/data/vehicles/epa_test_car_list_2022_part.csv" > "$work/epa100.csv"
failed=0
same() {  # same NAME ARGS...: serial and two-rank stdout identical, both exit 0
  local name=$1; shift
  "$rollsim" "$@" > "$work/serial.out" 2> "$work/serial.err"; local s=$?
  timeout 120 "${mpirun[@]}" "$rollsim" "$@" > "$work/mpi.out" 2> "$work/mpi.err"; local m=$?
  if [ $s -ne 0 ] || [ $m -ne 0 ]; then
    echo "FAIL $name: exit serial $s, mpirun $m"; cat "$work/serial.err" "$work/mpi.err"; failed=1; return
  fi
  # diagnose-bench's last line is its own wall time, which no two runs share.
  if [ "$name" = diagnose-bench ]; then tail -1 "$work/mpi.out" > "$work/mpi.last"; sed -i '$d' "$work/serial.out" "$work/mpi.out"; fi
  if cmp -s "$work/serial.out" "$work/mpi.out" && [ -s "$work/serial.out" ]; then
    echo "ok   $name ($(wc -l < "$work/serial.out") lines identical)"
  else
    echo "FAIL $name: outputs differ"; diff "$work/serial.out" "$work/mpi.out" | head -20; failed=1
  fi
}
camry="$shared/data/recordings/anl_d3_2018_toyota_camry"
printf 'group,vehicle,recording\nhot,camry_2018,%s\nhot,camry_2018,%s\nhighway,camry_2018,%s\n' \
  "$camry/61811012_test_data.csv" "$camry/61811014_test_data.csv" "$camry/61811013_test_data.csv" > "$work/fleet.csv"
same sweep-replay sweep --tyre nominal --vehicle ev --cycle wltc --param pressure --from 1.8 --to 3.2 --steps 6 \
  --param width --from 165 --to 195 --steps 4 --replay
same compare-replay compare --vehicle ev --catalogue --replay --csv
same validate validate --epa-test-car-list "$work/epa100.csv" --json
same fleet diagnose --fleet "$work/fleet.csv"
same diagnose-bench diagnose-bench --quick --seeds 1 --null-seeds 1
# ... and that line counts the ranks beside each one's threads ("on 2 threads" hid them: session 23's notes).
if grep -q "threads* on each of 2 MPI ranks$" "$work/mpi.last"; then echo "ok   diagnose-bench names its ranks"
else echo "FAIL diagnose-bench's time line: $(cat "$work/mpi.last")"; failed=1; fi
# A command that does not split its cases runs on rank 0 alone: its output as one process prints it, and a report
# written once (two ranks each cleaning up the other's figures could leave it incomplete; session 23's notes).
same simulate simulate --vehicle ev --tyre 155-70R19
rm -rf "$work/report" "$work/report1"
diag=(diagnose --vehicle camry_2018 --preset anl_d3 --recording "$camry/61811012_test_data.csv" --report)
"$rollsim" "${diag[@]}" "$work/report1" > /dev/null 2>&1
if "${mpirun[@]}" "$rollsim" "${diag[@]}" "$work/report" > "$work/diag.out" 2>&1 && [ -s "$work/report/report.html" ] &&
   [ "$(ls "$work/report")" = "$(ls "$work/report1")" ]; then
  echo "ok   diagnose --report under mpirun: $(ls "$work/report" | wc -l) files, as one process writes them"
else echo "FAIL diagnose --report under mpirun"; tail -5 "$work/diag.out"; ls "$work/report" "$work/report1"; failed=1; fi
# The forward sweep, written to a file by rank 0 alone: the serial stdout's bytes.
args=(sweep --tyre nominal --vehicle ev --cycle nedc --param pressure --from 2 --to 3 --steps 4)
"$rollsim" "${args[@]}" > "$work/s.csv"
"${mpirun[@]}" "$rollsim" "${args[@]}" --output "$work/m.csv"
if cmp -s "$work/s.csv" "$work/m.csv"; then echo "ok   sweep-forward --output"; else echo "FAIL sweep --output differs"; failed=1; fi
# A group that cannot be read on rank 1 ends both ranks with its manifest line, printed once.
printf 'group,vehicle,recording,columns\nok,camry_2018,%s,\nbad,camry_2018,%s,speed_kmh=Nope\n' \
  "$camry/61811012_test_data.csv" "$camry/61811012_test_data.csv" > "$work/bad.csv"
timeout 60 "${mpirun[@]}" "$rollsim" diagnose --fleet "$work/bad.csv" > "$work/bad.out" 2> "$work/bad.err"; code=$?
if [ $code -ne 0 ] && [ $code -ne 124 ] && [ "$(grep -c "group 'bad' (line 3)" "$work/bad.err")" -eq 1 ] && [ ! -s "$work/bad.out" ]; then
  echo "ok   failing case on rank 1: exit $code, named once"
else
  echo "FAIL failing case: exit $code (124: hung)"; cat "$work/bad.err"; failed=1
fi
for n in 2 3; do
  if timeout 60 "$mpiexec" -n $n --oversubscribe $([ "$(id -u)" -eq 0 ] && echo --allow-run-as-root) "$check"; then :; else
    echo "FAIL distribute_check on $n ranks"; failed=1
  fi
done
exit $failed
