#!/usr/bin/env bash
# The README's two commands on a fresh machine. Builds a minimal Debian 12 root (debootstrap --variant=minbase),
# installs only git and make in it, clones the committed HEAD of this repository into it and runs, as root inside
# the chroot, the commands of the README's first ```sh block (make run, then make test) in order. Prints PASS or
# FAIL and the wall time of every step; exits 0 only when all passed. Not part of `make test`: it needs root,
# mount and a Debian mirror, and took 3.5 to 7.5 minutes here (a near mirror, 2 shared cores).
#
#   sudo bash tests/fresh_machine.sh [--root DIR] [--mirror URI] [--keep]
#
#   --root DIR    where the root is built (MICA_FRESH_ROOT; default a new /var/tmp/mica-fresh.XXXXXX). DIR must
#                 not exist or be empty; it is removed at the end unless --keep.
#   --mirror URI  the Debian mirror (MICA_FRESH_MIRROR; default the URI apt on this machine uses for bookworm).
#   --keep        keep the root (unmounted) for a look afterwards (MICA_FRESH_KEEP=1).
#
# Mounts (proc, sys, dev, dev/pts, dev/shm) are undone and the root removed on every exit, failure or interrupt.
set -u
SUITE=bookworm
NEED_MB=2500                       # a full run used 1.24 GB (root, packages, build, test output)
root=${MICA_FRESH_ROOT:-} mirror=${MICA_FRESH_MIRROR:-} keep=${MICA_FRESH_KEEP:-0}
while [ $# -gt 0 ]; do
  case $1 in
    --root) root=${2:?--root needs a directory}; shift 2 ;;
    --mirror) mirror=${2:?--mirror needs a URI}; shift 2 ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "fresh_machine: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done

say() { echo "fresh_machine: $*"; }
die() { echo "fresh_machine: $*" >&2; exit 2; }

[ "$(id -u)" = 0 ] || die "needs root (debootstrap, chroot and mount); run it with sudo"
for tool in debootstrap chroot mount umount git; do
  command -v "$tool" >/dev/null || die "needs $tool (apt-get install debootstrap)"
done
repo=$(git -C "$(dirname "$0")" rev-parse --show-toplevel) || die "$(dirname "$0") is not in a git repository"
[ -z "$(git -C "$repo" status --porcelain --untracked-files=no)" ] \
  || say "note: $repo has uncommitted changes; only the committed HEAD is tested"

# The mirror apt on this machine uses for the suite (read from apt's configuration, not a fixed host name), and
# every source of the suite's family (bookworm, bookworm-updates, bookworm-security) to give the chroot's apt.
host_sources() {
  apt-get indextargets --no-release-info --format '$(REPO_URI) $(RELEASE) $(COMPONENT)' 'Created-By: Packages' \
    2>/dev/null | awk -v s="$SUITE" '$2 == s || index($2, s "-") == 1' | sort -u
}
host_mirror=$(host_sources | awk -v s="$SUITE" '$2 == s { print $1; exit }')
[ -n "$mirror" ] || mirror=$host_mirror
[ -n "$mirror" ] || die "apt on this machine has no source for $SUITE; give one with --mirror URI or MICA_FRESH_MIRROR"

# The root directory and its free space
if [ -z "$root" ]; then
  mkdir -p /var/tmp && root=$(mktemp -d /var/tmp/mica-fresh.XXXXXX) || die "cannot create a directory in /var/tmp"
else
  [ ! -e "$root" ] || [ -z "$(ls -A "$root" 2>/dev/null)" ] || die "$root exists and is not empty; give a new --root"
  mkdir -p "$root" || die "cannot create $root"
fi
root=$(cd "$root" && pwd -P)
[ "$root" != / ] || die "the root cannot be /"
[[ $root != *[[:space:]]* ]] || die "the root path must not contain white space: $root"
free_mb=$(df -Pm "$root" | awk 'NR == 2 { print $4 }')
say "root $root ($free_mb MB free), mirror $mirror, suite $SUITE"
if [ "${free_mb:-0}" -lt "$NEED_MB" ]; then
  rmdir "$root" 2>/dev/null
  die "only $free_mb MB free under $root; the run needs about $NEED_MB MB: give --root on a larger file system"
fi

# Cleanup on every exit: stop what still runs inside the root, undo the mounts (innermost first), remove the root.
child= names=() results=() times=() step_name= step_t0=
in_root_pids() {
  local p
  for p in /proc/[0-9]*; do
    [ "$(readlink "$p/root" 2>/dev/null)" = "$root" ] && echo "${p#/proc/}"
  done
}
process_tree() { # PID and all its descendants
  local c
  for c in $(grep -lx "PPid:[[:space:]]*$1" /proc/[0-9]*/status 2>/dev/null | cut -d/ -f3); do process_tree "$c"; done
  echo "$1"
}
mounted_under_root() { awk -v r="$root" '$2 == r || index($2, r "/") == 1 { print $2 }' /proc/self/mounts; }
cleanup() {
  local rc=$? m pids
  trap - EXIT INT TERM
  [ -z "$child" ] || kill $(process_tree "$child") 2>/dev/null
  pids=$(in_root_pids)
  if [ -n "$pids" ]; then
    kill $pids 2>/dev/null; sleep 2
    pids=$(in_root_pids); [ -z "$pids" ] || kill -KILL $pids 2>/dev/null
  fi
  # ours and any debootstrap left (it mounts proc and sys itself), the latest first
  for m in $(mounted_under_root | tac); do
    umount "$m" 2>/dev/null || umount -l "$m" || say "cannot unmount $m"
  done
  if [ -n "$(mounted_under_root)" ]; then
    say "still mounted, so $root is NOT removed: $(mounted_under_root | tr '\n' ' ')"
  elif [ "$keep" = 1 ]; then
    say "kept $root"
  else
    rm -rf --one-file-system "$root" && say "removed $root"
  fi
  exit "$rc"
}
trap cleanup EXIT
# stopped NAME STATUS: the step under way is recorded as stopped, the summary printed, the script exits STATUS.
stopped() {
  trap - INT TERM
  [ -z "$step_name" ] || { names+=("$step_name"); results+=("STOPPED ($1)"); times+=($(($(date +%s) - step_t0))); }
  summary; say "FAIL (stopped by SIG$1)"; exit "$2"
}
trap 'stopped INT 130' INT
trap 'stopped TERM 143' TERM

# step NAME COMMAND...: runs it in the background (so an interrupt is handled at once), records PASS/FAIL and time.
step() {
  local rc
  step_name=$1 step_t0=$(date +%s)
  shift
  say "=== $step_name"
  "$@" & child=$!
  wait "$child"; rc=$?; child=
  names+=("$step_name"); times+=($(($(date +%s) - step_t0))); step_name=
  if [ "$rc" -eq 0 ]; then results+=(PASS); else results+=("FAIL (exit $rc)"); fi
  return "$rc"
}
summary() {
  local i
  echo
  for i in "${!names[@]}"; do
    printf 'fresh_machine: %-42s %-14s %4d min %02d s\n' "${names[i]}" "${results[i]}" \
      $((times[i] / 60)) $((times[i] % 60))
  done
}
finish() { summary; say "$1"; [ "$1" = PASS ]; exit $?; }

mount_in_root() { # mount_in_root TARGET MOUNT-ARGS...
  local target=$root/$1
  shift
  mkdir -p "$target" && mount "$@" "$target"
}
in_root() { chroot "$root" /usr/bin/env -i HOME=/root TERM="${TERM:-dumb}" \
  PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin "$@"; }

# The chroot's apt sources: this machine's sources of the suite family, with the suite's mirror replaced.
write_sources() {
  rm -f "$root/etc/apt/sources.list"
  { [ -z "$host_mirror" ] || host_sources; echo "$mirror $SUITE main"; } |
    awk -v h="$host_mirror" -v m="$mirror" 'h != "" && $1 == h { $1 = m } { print }' | sort -u |
    awk '{ s[$1] = s[$1] (index(" " s[$1] " ", " " $2 " ") ? "" : " " $2)
           c[$1] = c[$1] (index(" " c[$1] " ", " " $3 " ") ? "" : " " $3) }
         END { for (u in s) printf "Types: deb\nURIs: %s\nSuites:%s\nComponents:%s\n" \
               "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg\n\n", u, s[u], c[u] }' \
    > "$root/etc/apt/sources.list.d/debian.sources"
  sed 's/^/    /' "$root/etc/apt/sources.list.d/debian.sources"
}

# What a freshly installed machine has and debootstrap does not set up: a resolver, /etc/hosts, the mounts.
prepare_root() {
  write_sources || return 1
  cp -L /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null
  printf '127.0.0.1\tlocalhost\n127.0.1.1\t%s\n::1\tlocalhost ip6-localhost ip6-loopback\n' "$(uname -n)" \
    > "$root/etc/hosts"
  mount_in_root proc -t proc proc && mount_in_root sys -t sysfs sys && mount_in_root dev --bind /dev &&
    mount_in_root dev/pts --bind /dev/pts && mount_in_root dev/shm -t tmpfs -o mode=1777 tmpfs
}
install_git_make() {
  in_root apt-get update -q &&
    in_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends git make
}

clone_repo() {
  git -C "$repo" bundle create --quiet "$root/usr/src/mica.bundle" HEAD &&
    in_root git -c advice.detachedHead=false clone -q /usr/src/mica.bundle /usr/src/mica &&
    rm -f "$root/usr/src/mica.bundle" && in_root git -C /usr/src/mica log --oneline -1
}

# The commands of the README's first ```sh block, comments stripped: each must be `make TARGET`.
readme_commands() {
  awk '/^```sh$/ { f = 1; next } f && /^```/ { exit } f' "$root/usr/src/mica/README.md" |
    sed 's/#.*//; s/^ *//; s/ *$//' | sed '/^$/d'
}

step "debootstrap --variant=minbase $SUITE" \
  debootstrap --variant=minbase "$SUITE" "$root" "$mirror" || finish FAIL
prepare_root || { say "cannot set up the root (sources, mounts)"; finish FAIL; }
step "apt-get install git make (no recommends)" install_git_make || finish FAIL
step "git clone $(git -C "$repo" rev-parse --short HEAD)" clone_repo || finish FAIL
mapfile -t commands < <(readme_commands)
say "the README's commands: $(IFS=';'; echo "${commands[*]}" | sed 's/;/; /g')"
[ "${#commands[@]}" -gt 0 ] || { say "README.md has no \`\`\`sh block of commands"; finish FAIL; }
for c in "${commands[@]}"; do
  [[ $c =~ ^make\ [a-z][a-z-]*$ ]] || { say "README command '$c' is not 'make TARGET'; not run"; finish FAIL; }
done
for c in "${commands[@]}"; do
  step "$c" in_root bash -c "cd /usr/src/mica && $c" || finish FAIL
done
# A test that skips because the machine lacks something (mpirun cannot start) is a missing dependency here.
skipped=$(grep -l '### SKIPPED' "$root"/usr/src/mica/build/test-out/*.log 2>/dev/null | xargs -r -n1 basename)
if [ -n "$skipped" ]; then
  names+=("tests that skipped"); results+=("FAIL"); times+=(0)
  say "skipped on the fresh machine: $(echo $skipped)"; finish FAIL
fi
say "disk used by the root: $(du -sm --one-file-system "$root" | cut -f1) MB"
finish PASS
