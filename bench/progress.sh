# The shell benchmarks' progress bar with ETA (source it): on stderr and only when it is a
# terminal, so that stdout carries nothing but the results. The same bar as bench/progress.py.

# progress LABEL DONE TOTAL START: DONE of TOTAL steps, begun at START (date +%s.%N).
progress() {
  [ -t 2 ] || return 0
  awk -v l="$1" -v d="$2" -v t="$3" -v s="$4" -v now="$(date +%s.%N)" 'BEGIN {
    f = t > 0 ? d / t : 1; if (f > 1) f = 1
    bar = ""; for (i = 0; i < int(30 * f); i++) bar = bar "#"
    eta = f > 0 ? sprintf("%6.1f s", (now - s) * (1 - f) / f) : "     ? s"
    printf "\r%-28s [%-30s] %5.1f%%  ETA %s ", l, bar, 100 * f, eta > "/dev/stderr" }'
}

# progress_clear: erases the bar, before a result line or at the end.
progress_clear() {
  if [ -t 2 ]; then printf '\r\033[K' >&2; fi
  return 0
}
