#!/usr/bin/env bash
# The MLS accuracy study of seed 001 §3.2 (Figs 3.41-3.61, Table 3.1): runs every deck of this
# directory with bin/mica, copies each error chart to figures/, prints one table per deck and
# writes the tables to results.md. Takes a few seconds.
#
#   bash examples/mls-accuracy/run.sh              # the decks as shipped (c = 35, as printed)
#   bash examples/mls-accuracy/run.sh --c 5.5      # the same decks with --set parameters.c=5.5
#   bash examples/mls-accuracy/run.sh order2_radii # only some decks (tables to out/results.md)
#
# Outputs, relative to this directory (<s> is empty, or _c<value> with --c):
#   out/<deck><s>/       mica's output (summary.json, mls.csv, mls_error.png/.svg, ...), gitignored
#   figures/<deck><s>.png  the error chart re-drawn smaller (cairo PNG: libgd has no dash patterns); each error axis starts at
#                        the decade of the 3rd percentile of its errors (the deep dips where an
#                        error changes sign carry no information)
#   figures/<deck>.svg   the same chart as SVG (as-printed c only, to keep the figures small)
#   results<s>.md        the tables (all decks only; a subset goes to out/results<s>.md)
# Needs bin/mica (built by make if missing), awk, sed, gnuplot.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
rel=${here#"$root"/}
cd "$root"

c=""
decks=()
while [ $# -gt 0 ]; do
    case $1 in
        --c) c=${2:?"--c needs a value"}; shift 2 ;;
        --c=*) c=${1#--c=}; shift ;;
        -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) echo "run.sh: unknown option $1" >&2; exit 2 ;;
        *) decks+=("${1%.cfg}"); shift ;;
    esac
done
subset=1
if [ ${#decks[@]} -eq 0 ]; then
    subset=0
    decks=(order0_radii order1_radii order2_radii order3_radii
           weights_order1 weights_order2 weights_order3 support_table)
fi

suffix=""
set_c=()
if [ -n "$c" ]; then
    suffix="_c$c"
    set_c=(--set "parameters.c=$c")
fi

[ -x bin/mica ] || make >/dev/null
command -v gnuplot >/dev/null || { echo "run.sh: gnuplot not found" >&2; exit 1; }
mkdir -p "$rel/out" "$rel/figures"

results="$rel/results$suffix.md"
[ "$subset" = 1 ] && results="$rel/out/results$suffix.md"

# One markdown table from summary.json (pretty-printed, one member per line).
summary_table() {
    awk '
        /"variants": \[/ { inv = 1; next }
        inv && /^  \]/    { inv = 0 }
        !inv { next }
        {
            line = $0
            sub(/^[ \t]*"/, "", line); sub(/,[ \t]*$/, "", line)
            k = line; sub(/".*/, "", k)
            v = line; sub(/^[^:]*:[ \t]*/, "", v); gsub(/"/, "", v)
            val[k] = v
        }
        inv && /^    }/ {
            printf "| %s | %d-%d | %.2e | %.2e | %.2e | %.2e | %.2e | %.2e | %.3g |\n", val["name"],
                val["support_min"], val["support_max"], val["err_f_max"], val["err_f_rms"],
                val["err_dx_max"], val["err_dx_rms"], val["err_dxx_max"], val["err_dxx_rms"],
                val["evals_per_s"]
            delete val
        }
        BEGIN {
            print "| variant | support | err_f max | err_f rms | err_dx max | err_dx rms | err_dxx max | err_dxx rms | evals/s |"
            print "|---|---|---|---|---|---|---|---|---|"
        }' "$1"
}

# Boundary against interior from mls.csv: largest errors in the outermost particle spacing
# (|x| >= 4, "boundary") and inside it (|x| < 4, "interior").
edge_table() {
    awk -F, '
        BEGIN {
            print "| variant | f: boundary / interior | df: boundary / interior | ddf: boundary / interior |"
            print "|---|---|---|---|"
        }
        NR == 1 || $2 != "line" { next }
        {
            v = $1; gsub(/"/, "", v)
            if (!(v in seen)) { seen[v] = 1; order[++n] = v }
            b = ($5 >= 4 - 1e-9 || $5 <= -4 + 1e-9) ? "b" : "i"
            if ($11 + 0 > ef[v, b]) ef[v, b] = $11 + 0
            if ($14 + 0 > ed[v, b]) ed[v, b] = $14 + 0
            if ($17 + 0 > edd[v, b]) edd[v, b] = $17 + 0
        }
        END {
            for (j = 1; j <= n; j++) {
                v = order[j]
                printf "| %s | %.2e / %.2e | %.2e / %.2e | %.2e / %.2e |\n", v,
                    ef[v, "b"], ef[v, "i"], ed[v, "b"], ed[v, "i"], edd[v, "b"], edd[v, "i"]
            }
        }' "$1"
}

{
    echo "# MLS accuracy study, seed 001 §3.2: results${c:+ with c = $c}"
    echo
    echo "Written by \`run.sh${c:+ --c $c}\`. f = 100 (1 - (x/c)^2)^5 (1 - (y/c)^2)^5 (1 - (z/c)^2)^5 with"
    echo "c = ${c:-35 (as printed)}; 11^3 particles on [-5, 5]^3; 201 samples on the line (-5,0,0)-(5,0,0); box supports."
    echo "Errors are |approximation - exact| / max |exact| over the line (f, df/dx, d2f/dx2)."
    echo "Boundary: the outermost particle spacing, 4 <= |x| <= 5; interior: |x| < 4."
    echo "evals/s (shape functions with first and second derivatives) depends on the machine and its load."
} > "$results"

for d in "${decks[@]}"; do
    deck="$rel/$d.cfg"
    [ -f "$deck" ] || { echo "run.sh: no deck $deck" >&2; exit 1; }
    out="$rel/out/$d$suffix"
    rm -rf "$out"
    bin/mica mls "$deck" -o "$out" ${set_c[@]+"${set_c[@]}"} > "$out.log" 2>&1 ||
        { cat "$out.log" >&2; echo "run.sh: mica failed on $deck" >&2; exit 1; }

    # The chart, re-drawn from mica's own gnuplot script: a smaller PNG, and each error
    # axis starting at the decade of the panel's 3rd percentile (the deep dips where an error
    # changes sign carry no information).
    read -r lo_f lo_d lo_dd < <(awk '
        function floor10(v,   e) { e = log(v) / log(10); return (e == int(e) || e > 0) ? int(e) : int(e) - 1 }
        !/^#/ && NF >= 4 {
            for (k = 2; k <= 4; k++) {
                v = $k + 0; n[k]++
                e = (v > 0) ? floor10(v) : -20; if (e < -20) e = -20
                cnt[k, e]++
                if (v > mx[k]) mx[k] = v
            }
        }
        END {
            for (k = 2; k <= 4; k++) {
                s = 0
                for (e = -20; e < 10; e++) { s += cnt[k, e]; if (s >= 0.03 * n[k]) break }
                top = (mx[k] > 0) ? floor10(mx[k]) : -19
                if (e > top - 1) e = top - 1
                printf "%s1e%d", (k > 2 ? " " : ""), e
            }
            print ""
        }' "$out/mls_line.dat")
    sed -e "s/^set terminal pngcairo .*/set terminal pngcairo size 760,900 noenhanced/" \
        -e "s/^set terminal svg .*/set terminal svg size 760,900 noenhanced/" \
        -e "s/^\(set multiplot layout 3,1 title '.*\)'\$/\1${c:+, c = $c}'/" \
        -e "s/^\(set ylabel 'relative error of f'\)\$/\1\nset yrange [$lo_f:*]/" \
        -e "s/^\(set ylabel 'relative error of df\/dx'\)\$/\1\nset yrange [$lo_d:*]/" \
        -e "s/^\(set ylabel 'relative error of d2f\/dx2'\)\$/\1\nset yrange [$lo_dd:*]/" \
        -e "s/'mls_error\.\(png\|svg\)'/'figure.\1'/" \
        "$out/mls_chart.gp" > "$out/figure.gp"
    (cd "$out" && gnuplot figure.gp)
    cp "$out/figure.png" "$rel/figures/$d$suffix.png"
    [ -n "$c" ] || cp "$out/figure.svg" "$rel/figures/$d.svg"

    {
        echo
        echo "## $d${c:+ (c = $c)}"
        echo
        echo "$(sed -n '1s/^# //p' "$deck")  "
        echo "Figure: [figures/$d$suffix.png](figures/$d$suffix.png)"
        echo
        summary_table "$out/summary.json"
        echo
        echo "Largest errors, boundary / interior:"
        echo
        edge_table "$out/mls.csv"
    } | tee -a "$results"
done
echo
echo "tables written to $results; figures in $rel/figures/"
