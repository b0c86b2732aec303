# tally.sh — the pass/fail bookkeeping shared by the interpreter test
# scripts (run.sh, outpaths.sh), sourced by both. A case calls
# `because REASON` for each failed check; `tally FILES...` closes it,
# showing FILES (the case's output) when it failed.
npass=0
nfail=0
because() { why="$why${why:+; }$*"; }
tally() {
  if [ -z "$why" ]; then
    echo "ok   $name"
    npass=$((npass + 1))
  else
    echo "FAIL $name: $why"
    sed -e 's/^/     | /' "$@" | head -n 20
    nfail=$((nfail + 1))
  fi
}
