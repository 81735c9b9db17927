#!/usr/bin/env bash
# No deck string reaches gnuplot as a command (issue 17): every charting command — mls, sweep, study,
# stability (`mica run` draws no chart) — with a hostile problem title, variant, choice, probe, reference and
# axis names, and an output directory with quotes, backquotes, $(...), a newline, !, @ and ;. Each injected
# command would create a file pwned*; none may appear, the PNG and SVG are drawn, gnuplot reports no error,
# the text is in the script as one single-quoted literal (quotes doubled, line breaks as spaces:
# mica_gnuplot_quote) and in the SVG as written (the terminals are noenhanced: _ ^ { } & ~ \ print as such).
source "$(dirname "$0")/common.bash"
root="$OUT_DIR/chart_injection"
rm -rf "$root" && mkdir -p "$root" || fail "cannot make $root"
cd "$root" || fail "cannot enter $root"
repo=$(cd "$OLDPWD" && pwd)

H=$'t_1^2 {a} & ~ it\'s "q" `touch pwned1` $(touch pwned2) ; @m \\ end\n!touch pwned3\n#'
D="o'q\"b\`touch pwned4\`\$(touch pwned5);!x @y"$'\n'"z"
# the text as a libconfig string for --set
cfg() { local s=${1//\\/\\\\}; s=${s//\"/\\\"}; s=${s//$'\n'/\\n}; printf '"%s"' "$s"; }
# the text as mica_gnuplot_quote writes it, and as the SVG shows it (XML's own escapes undone)
literal() { local s=${1//$'\n'/ }; printf "'%s'" "${s//\'/\'\'}"; }
svg_text() { sed -e 's/&lt;/</g; s/&gt;/>/g; s/&quot;/"/g; s/&apos;/'"'"'/g; s/&amp;/\&/g' "$1"; }

# check NAME DIR SCRIPT CHART TEXT...: nothing ran, CHART.png/.svg drawn, a clean gnuplot.log, and each TEXT in
# the script as a literal and in the SVG as written
check() {
  local name=$1 dir=$2 script=$3 chart=$4; shift 4
  local found
  found=$(find . -name 'pwned*'; find "$repo" -maxdepth 1 -name 'pwned*')
  [ -z "$found" ] || fail "$name: an injected command ran: $found"
  [ -s "$dir/$chart.png" ] && [ -s "$dir/$chart.svg" ] || fail "$name: $chart.png/.svg not drawn"
  # gnuplot's only message allowed: long titles that do not fit the key's width
  found=$(grep -v 'warning: Warning - difficulty fitting plot titles into key' "$dir/gnuplot.log")
  [ -z "$found" ] || fail "$name: gnuplot.log: $found"
  local t
  for t in "$@"; do
    grep -qF -- "$(literal "$t")" "$dir/$script" || fail "$name: $script lacks the literal $(literal "$t")"
    svg_text "$dir/$chart.svg" | grep -qF -- "${t//$'\n'/ }" || fail "$name: $chart.svg does not show '$t' as written"
  done
  ok "$name: nothing ran, $chart.png/.svg drawn, gnuplot.log clean, $# deck strings as literals"
}
run() { # run NAME COMMAND...: mica must succeed
  local name=$1; shift
  "$MICA" "$@" > "$name.log" 2>&1 || fail "mica $1 failed: $(tail -n 3 "$name.log")"
}

# mls: the title and the variant names
run mls mls "$repo/input/mls_quickstart.cfg" -o "$D/mls" --set "problem.title=$(cfg "$H")" \
  --set "study.variants=({ name = $(cfg "v$H"); mls = { dilation = 2.2; }; }, { name = $(cfg "w'"); mls = { dilation = 3.2; }; })"
check mls "$D/mls" mls_chart.gp mls_error "$H" "v$H" "w'"

# sweep: the title, x and y labels, a probe named in the default y label and the script, a reference's name
probe="p$H"
sweep=(sweep "$repo/input/sweep_cantilever.cfg" --set "problem.title=$(cfg "$H")"
  --set "output.probes=({ name = $(cfg "$probe"); point = [\"L\", \"0\"]; field = \"uy\"; })"
  --set "sweep.probe=$(cfg "$probe")" --set 'sweep.parameters=({ path = "parameters.L"; values = [4.0, 8.0]; })'
  --set "sweep.analytic=({ name = $(cfg "a$H"); f = \"P*x^3/(3*E*I)\"; })")
run sweep "${sweep[@]}" -o "$D/sweep" --set "sweep.xlabel=$(cfg "x$H")" --set "sweep.ylabel=$(cfg "y$H")"
check sweep "$D/sweep" sweep_chart.gp sweep "$H" "x$H" "y$H" "a$H"
run sweep_probe "${sweep[@]}" -o "$D/sweep_probe" --set 'sweep.ylabel=""'
words=${probe//_/ }
check "sweep, default y label" "$D/sweep_probe" sweep_chart.gp sweep "$words (probe of uy)"
grep -qF -- "# mica sweep: $(literal "$probe") against" "$D/sweep_probe/sweep_chart.gp" ||
  fail "sweep: the script's comment does not hold the probe's name as a literal"
ok "sweep: the probe's name in the script's comment as a literal"

# study: the title, a choice's name (curve labels and the front's labels, a data file), a probe as the error
run study study "$repo/input/study_timoshenko.cfg" -o "$D/study" --set "problem.title=$(cfg "$H")" \
  --set "output.probes=({ name = $(cfg "$probe"); point = [\"L\", \"0\"]; field = \"uy\"; })" \
  --set "study.error=$(cfg "$probe")" --set 'study.reference="P*L^3/(3*E*I)"' \
  --set "study.choices=({ path = \"parameters.k\"; name = $(cfg "c$H"); values = [1, 2]; }, { path = \"parameters.m\"; values = [2, 4]; })"
check study "$D/study" study_chart.gp study_time "$H: relative error of $probe against time" "relative error of $probe"
check "study, dofs" "$D/study" study_chart.gp study_dofs "$H: relative error of $probe against dofs"
svg_text "$D/study/study_time.svg" | grep -qF -- "c${H//$'\n'/ }" || fail "study: the choice's name is not in the chart"
ok "study: the choice's name in the curve labels as written"

# stability: its charts hold no deck string; the output directory is the hostile one
run stability stability "$repo/input/free_block.cfg" -o "$D/stability" --set "problem.title=$(cfg "$H")" \
  --set stability.patch=false --set 'stability.inf_sup_counts=[5, 9]'
check stability "$D/stability" spectrum.gp spectrum
check "stability, inf-sup" "$D/stability" inf_sup.gp inf_sup
