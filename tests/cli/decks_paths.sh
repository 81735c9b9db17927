# Nothing the project ships points outside the repository: a clone has no ../shared/ beside it, no /work,
# no one's home directory (docs/verification.md §References holds the references the decks cite).
#  - every deck (input/, examples/, tests/decks/, bench/): no such path or file name in its text; every file a
#    setting names (geometry.mesh, sweep.experiments.[].file, relative to the deck) exists inside the
#    repository; every repository path a comment names (a token with a "/" ending in .cfg, .md, .c, .h, .sh,
#    .py, .msh, .geo, .csv) exists, relative to the repository or to the deck;
#  - the docs (docs/, README.md, the examples' READMEs and notes), src/ and include/ (messages and comments),
#    the tests and the Makefile: no such path or file name.
source "$(dirname "$0")/common.bash"
root=$(pwd -P)

# paths and names of files that only exist outside the repository
outside='(\.\./)+shared/|(^|[^A-Za-z0-9_./-])shared/(reference|design|seeds|hooks)|benchmarks\.md|design\.md|peers\.md|/work/|/home/|/root/|seed[s]?/[0-9]'
found=$(grep -rnEI "$outside" input examples bench docs README.md src include tests Makefile 2>/dev/null \
  | grep -v '^bench/results/\|^tests/cli/decks_paths.sh:' || true)
[ -z "$found" ] || fail "text that points outside the repository:"$'\n'"$found"
ok "no deck, doc, source file, message or test names ../shared, design.md, benchmarks.md, /work, /home or /root"

inside() { case "$1" in "$root"/*) return 0 ;; *) return 1 ;; esac; }
decks=$(find input examples tests/decks bench -name '*.cfg' | sort)
n=0 files=0 named=0
for deck in $decks; do
  n=$((n + 1))
  dir=$(dirname "$deck")
  # absolute paths in settings ("/..." as a string value)
  if grep -nE '=[[:space:]]*"/' "$deck" > /dev/null; then fail "$deck: a setting is an absolute path: $(grep -nE '=[[:space:]]*"/' "$deck")"; fi
  # files named by settings
  while IFS= read -r value; do
    [ -n "$value" ] || continue
    path=$(realpath -m "$dir/$value")
    inside "$path" || fail "$deck: '$value' resolves to $path, outside the repository"
    [ -f "$path" ] || fail "$deck: '$value' ($path) does not exist"
    files=$((files + 1))
  done < <(grep -oE '(mesh|file)[[:space:]]*=[[:space:]]*"[^"]*"' "$deck" | sed 's/^[^"]*"//; s/"$//')
  # repository files named in comments
  while IFS= read -r token; do
    case "$token" in out/* | */out/* | http*) continue ;; esac
    ok_path=0
    for base in "$root" "$root/$dir"; do
      p=$(realpath -m "$base/$token")
      inside "$p" && [ -e "$p" ] && ok_path=1
    done
    [ $ok_path = 1 ] || fail "$deck: the comment names $token, which is not in the repository"
    named=$((named + 1))
  done < <(grep -E '^[[:space:]]*#|#' "$deck" | sed 's/^[^#]*#//' \
           | grep -oE '[A-Za-z0-9_.-]*/[A-Za-z0-9_./-]*\.(cfg|md|c|h|sh|py|msh|geo|csv)\b' | sort -u)
done
ok "$n decks: $files files named by settings and $named repository paths named in comments, all inside the repository"
