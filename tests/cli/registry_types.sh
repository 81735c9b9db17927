# The registries of types (docs/architecture.md §Registries and settings) seen from the deck: a type's own
# settings, its default, and the refusal of a setting the chosen type does not read.
# - bc.alpha is declared by penalty (default 1e3) and nitsche (default 100), each its own: the summary's
#   bc_alpha is exactly 1000, 100, and 0 for lagrange (which has none); given, it is taken as given (7.5).
# - bc.alpha given with bc.method = "lagrange" is refused (exit 2, the line, the owning methods); so is
#   solver.petsc (petsc's own) with solver.linear = "umfpack" or "auto" in one process.
# - the choice lists and defaults come from the registries: `mica help run` lists bc.method
#   penalty|nitsche|lagrange|collocation (default "nitsche"), solver.linear auto|cholmod|umfpack|cholmod-sym|petsc (default "auto"),
#   problem.method efg|fe, quadrature.mode gauss|nodal|scni|nsni, and bc.alpha's two defaults.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/registry_types"
rm -rf "$work" && mkdir -p "$work"

deck=input/patch_linear.cfg
for pair in penalty:1000 nitsche:100 lagrange:0; do
  method=${pair%%:*} expected=${pair##*:}
  run_deck "$work/$method" $deck --set bc.method=$method
  got=$(json_value bc_alpha "$work/$method/summary.json")
  awk -v g="$got" -v e="$expected" 'BEGIN { exit !(g == e) }' || fail "$method: bc_alpha $got, expected $expected"
  ok "$method: bc_alpha $got (its own default)"
done
run_deck "$work/given" $deck --set bc.method=penalty --set bc.alpha=7.5
[ "$(json_value bc_alpha "$work/given/summary.json")" = 7.5 ] || fail "a given bc.alpha was not taken"
ok "a given bc.alpha is taken"

expect_failure 2 'bc.alpha is a setting of bc.method = "penalty/nitsche" only' -- \
  "$MICA" run $deck -o "$work/x" --set bc.method=lagrange --set bc.alpha=10
expect_failure 2 '--set bc.alpha=10' -- "$MICA" run $deck -o "$work/x" --set bc.method=lagrange --set bc.alpha=10
expect_failure 2 'solver.petsc is a setting of solver.linear = "petsc" only' -- \
  "$MICA" run $deck -o "$work/x" --set solver.linear=umfpack --set solver.petsc=gamg
expect_failure 2 'solver.linear is "auto" here' -- "$MICA" run $deck -o "$work/x" --set solver.petsc=gamg
[ ! -e "$work/x" ] || fail "a refused deck created its output directory"

help=$("$MICA" help run)
for line in 'bc.method +choice +"nitsche" +penalty\|nitsche\|lagrange\|collocation$' \
            'solver.linear +choice +"auto" +auto\|cholmod\|umfpack\|cholmod-sym\|petsc$' \
            'problem.method +choice +"efg" +efg\|fe$' 'quadrature.mode +choice +"gauss" +gauss\|nodal\|scni\|nsni$' \
            'solver.petsc +choice +"mumps" +mumps\|gamg\|gmg\|hypre\|asm-cholmod\|$' \
            'bc.alpha +float +- '; do
  grep -Eq "^$line" <<<"$help" || fail "mica help run lacks /$line/"
done
tr -s ' \n' ' ' <<<"$help" | grep -qF "(default: 1e3 with penalty, 100 with nitsche)" \
  || fail "mica help run does not give bc.alpha's defaults per method"
ok "choices and defaults from the registries in mica help run"
