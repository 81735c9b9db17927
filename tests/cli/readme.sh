# The README's quick start stays true to the Makefile: its first ```sh block is exactly `make run` and
# `make test` (the commands tests/fresh_machine.sh runs on a fresh Debian 12), and the Debian packages it names
# are exactly the Makefile's DEB_PKGS (what `make deps` installs), none missing, none extra.
source "$(dirname "$0")/common.bash"

commands=$(awk '/^```sh$/ { f = 1; next } f && /^```/ { exit } f' README.md | sed 's/#.*//; s/ *$//' | sed '/^$/d')
[ "$commands" = "make run"$'\n'"make test" ] \
  || fail "README.md's first sh block should be 'make run' then 'make test' (tests/fresh_machine.sh runs it): $commands"
ok "README's two commands: make run, make test"

# DEB_PKGS as make evaluates it (every := and +=), one package a line
makefile=$(env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s --no-print-directory \
  --eval 'readme-test-deb-pkgs: ; @echo $(DEB_PKGS)' readme-test-deb-pkgs) || fail "make cannot print DEB_PKGS"
makefile=$(tr -s ' ' '\n' <<<"$makefile" | sed '/^$/d' | sort)
[ "$(wc -l <<<"$makefile")" -ge 10 ] || fail "DEB_PKGS has too few packages to be real: $makefile"
[ -z "$(uniq -d <<<"$makefile")" ] || fail "DEB_PKGS names a package twice: $(uniq -d <<<"$makefile" | tr '\n' ' ')"

# The README's list: the code spans of the paragraph that begins "`make deps`, ..." that are package names
readme=$(awk '/^`make deps`/ { f = 1 } f && /^$/ { exit } f' README.md | grep -o '`[^`]*`' | tr -d '`' |
  grep -E '^[a-z0-9][a-z0-9.+-]+$' | sort)
[ -n "$readme" ] || fail "README.md has no paragraph beginning with \`make deps\` that lists the packages"

missing=$(comm -23 <(sort -u <<<"$makefile") <(sort -u <<<"$readme") | tr '\n' ' ')
extra=$(comm -13 <(sort -u <<<"$makefile") <(sort -u <<<"$readme") | tr '\n' ' ')
[ -z "$missing" ] || fail "README.md does not name these packages of the Makefile's DEB_PKGS: $missing"
[ -z "$extra" ] || fail "README.md names packages that DEB_PKGS does not install: $extra"
[ "$readme" = "$makefile" ] || fail "README.md names a package twice: $(uniq -d <<<"$readme" | tr '\n' ' ')"
ok "README names exactly the $(wc -l <<<"$makefile") packages of DEB_PKGS"
