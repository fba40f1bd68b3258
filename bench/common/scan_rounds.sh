# What the scan benchmarks share (sourced, after tests/common/st_build.sh):
# build an ST program as plcrt builds one, time it scan by scan with
# bench/aposs/driver.c's protocol (one line per round: "median NS p99 NS
# posa N bad N max NS"), ROUNDS rounds.
#   scan_rounds TAG DIR ALL.st DRIVER.c SCANS ROUNDS [LINK ARGS...]
# sets med, p99, moves (medians over the rounds), bad (the sum) and max
# (the quietest round's: on a shared machine a round's maximum is often
# another process's time slice, not the scan's); status 1 if the build or a
# round failed.
median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

scan_rounds() {
    local tag=$1 d=$2 src=$3 drv=$4 scans=$5 rounds=$6 r
    shift 6
    st_compile "$src" "$d" "$tag" || return 1
    st_link "$d" "$drv" "$d/prog" "$tag" "$@" || return 1
    : > "$d/rounds.txt"
    for r in $(seq "$rounds"); do
        "$d/prog" "$scans" >> "$d/rounds.txt" || return 1
    done
    med=$(awk '{ print $2 }' "$d/rounds.txt" | median)
    p99=$(awk '{ print $4 }' "$d/rounds.txt" | median)
    moves=$(awk '{ print $6 }' "$d/rounds.txt" | median)
    bad=$(awk '{ s += $8 } END { print s }' "$d/rounds.txt")
    max=$(awk '{ print $10 }' "$d/rounds.txt" | sort -n | head -1)
}
