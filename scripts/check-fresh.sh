#!/usr/bin/env bash
# Runs the README's two commands in a fresh Debian 12 (bookworm) root, as a new user would:
# bootstraps a minbase root with debootstrap (installed through apt-get if missing; the mirror
# is the one this machine's apt sources name), clones the committed HEAD of this checkout into
# /root/covrast inside it (nothing beside it: no ../shared), mounts /proc, /sys, /dev and
# /dev/pts, and runs in a chroot `bash scripts/render-default.sh`, then `bash scripts/test.sh`.
# Prints each step's wall time and exits 1 if a step fails. Runs as root (debootstrap, mount,
# chroot). Uncommitted changes of the checkout are not tested (the clone is of HEAD).
#
# Usage: scripts/check-fresh.sh [--render-only] [--keep] [ROOT_DIR]
#   --render-only  run only `bash scripts/render-default.sh`
#   --keep         keep the root after the run (a temporary one is removed otherwise)
#   ROOT_DIR       the root to use: bootstrapped if it does not hold one yet, reused (no
#                  bootstrap, packages already installed stay) if it does; never removed
#   --help         this text
set -euo pipefail

usage() { sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d' | sed 's/^# \{0,1\}//'; }

render_only=0
keep=0
root=
while [[ $# -gt 0 ]]; do
  case "$1" in
    --render-only) render_only=1 ;;
    --keep) keep=1 ;;
    -h | --help)
      usage
      exit 0
      ;;
    -*)
      echo "check-fresh: error: unknown option $1 (see --help)" >&2
      exit 2
      ;;
    *)
      if [[ -n "$root" ]]; then
        echo "check-fresh: error: more than one root directory given" >&2
        exit 2
      fi
      root=$1
      keep=1
      ;;
  esac
  shift
done

if [[ $(id -u) -ne 0 ]]; then
  echo "check-fresh: error: must run as root (debootstrap, mount and chroot need it)" >&2
  exit 2
fi

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && git rev-parse --show-toplevel)
head=$(git -C "$repo" rev-parse HEAD)
if [[ -n $(git -C "$repo" status --porcelain --untracked-files=no) ]]; then
  echo "check-fresh: note: the checkout has uncommitted changes; they are not tested (HEAD is)" >&2
fi

# The Debian mirror this machine uses: the first URI of a source for bookworm in the apt
# sources (deb822 .sources files and one-line .list files); Debian's own mirror otherwise.
mirror_of_host() {
  local file
  for file in /etc/apt/sources.list.d/*.sources; do
    [[ -f "$file" ]] || continue
    awk '/^URIs:/ {uri = $2} /^Suites:/ && / bookworm( |$)/ && uri != "" {print uri; exit}' \
      "$file"
  done
  for file in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [[ -f "$file" ]] || continue
    awk '$1 == "deb" && $0 ~ / bookworm / {for (i = 2; i <= NF; i++) if ($i ~ /^[a-z]+:\/\//) {print $i; exit}}' \
      "$file"
  done
}
mirror=$(mirror_of_host | awk 'NR == 1')
mirror=${mirror:-http://deb.debian.org/debian}

created=0
if [[ -z "$root" ]]; then
  root=$(mktemp -d /var/tmp/covrast-fresh.XXXXXX)
  created=1
fi
mkdir -p "$root"
root=$(cd "$root" && pwd)

mounts=()
cleanup() {
  local status=$? i
  for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do
    umount -R "${mounts[i]}" 2>/dev/null || umount -R -l "${mounts[i]}" || true
  done
  if [[ $created -eq 1 && $keep -eq 0 ]]; then
    if findmnt -rn -o TARGET | grep -q "^$root/"; then
      echo "check-fresh: $root still has mounts; not removed" >&2
    else
      rm -rf --one-file-system "$root"
    fi
  else
    echo "check-fresh: the root is kept in $root"
  fi
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

timed() { # NAME COMMAND...: runs the command, prints its wall time, fails the script if it fails
  local name=$1 start=$SECONDS status=0
  shift
  echo "check-fresh: $name"
  "$@" || status=$?
  echo "check-fresh: $name: $((SECONDS - start)) s, exit $status"
  if [[ $status -ne 0 ]]; then
    echo "check-fresh: FAILED: $name" >&2
    exit 1
  fi
}

bootstrap() {
  if ! command -v debootstrap >/dev/null 2>&1; then
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends debootstrap
  fi
  debootstrap --variant=minbase bookworm "$root" "$mirror"
}

if [[ -f "$root/etc/debian_version" && -x "$root/usr/bin/apt-get" ]]; then
  echo "check-fresh: reusing the root in $root (Debian $(cat "$root/etc/debian_version"))"
else
  echo "check-fresh: bootstrapping Debian 12 (minbase) from $mirror into $root"
  timed "debootstrap" bootstrap
fi

# apt inside the root reaches the same mirror: this machine's Debian sources (those naming
# debian.org or the mirror; other vendors' repositories are left out, their keys are not
# there), else the one debootstrap wrote. Name resolution as on this machine.
copied=0
for file in /etc/apt/sources.list.d/*.sources /etc/apt/sources.list.d/*.list; do
  [[ -f "$file" ]] || continue
  if grep -q -e 'debian\.org' -e "$mirror" "$file"; then
    cp "$file" "$root/etc/apt/sources.list.d/"
    copied=1
  fi
done
if [[ $copied -eq 1 ]]; then
  rm -f "$root/etc/apt/sources.list"
fi
cp -L /etc/resolv.conf "$root/etc/resolv.conf"

for dir in proc sys dev; do
  mkdir -p "$root/$dir"
done
mount -t proc proc "$root/proc"
mounts+=("$root/proc")
mount -t sysfs sysfs "$root/sys"
mounts+=("$root/sys")
# A plain bind of /dev made private at once, so that the mounts below it stay in the root.
mount --bind /dev "$root/dev"
mounts+=("$root/dev")
mount --make-private "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
mounts+=("$root/dev/pts")
mount -t tmpfs -o mode=1777 shm "$root/dev/shm"
mounts+=("$root/dev/shm")

# A fresh clone of HEAD, alone in /root: no ../shared beside it.
rm -rf "$root/root/covrast"
git clone -q "$repo" "$root/root/covrast"
git -C "$root/root/covrast" -c advice.detachedHead=false checkout -q "$head"
if [[ -e "$root/root/shared" ]]; then
  echo "check-fresh: error: $root/root/shared exists; the check needs a clone without ../shared" >&2
  exit 1
fi
echo "check-fresh: cloned $(git -C "$repo" log -1 --format='%h %s' "$head" | cut -c1-100)"

in_root() { # COMMAND: runs a shell command in /root/covrast in the root, with a clean environment
  chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM="${TERM:-dumb}" \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    bash -c "cd /root/covrast && $1"
}

# shellcheck disable=SC2016 # expanded in the root
timed "bash scripts/render-default.sh" in_root 'png=$(bash scripts/render-default.sh) && test -s "$png" && echo "rendered $png"'
if [[ $render_only -eq 0 ]]; then
  timed "bash scripts/test.sh" in_root 'bash scripts/test.sh'
fi
echo "check-fresh: all steps passed"
