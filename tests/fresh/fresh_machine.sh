#!/usr/bin/env bash
# The README's two commands on a fresh Debian 12 machine: a minimal Debian 12 root made with debootstrap
# (variant minbase: no git, no compiler, no Python) from the Debian archive this machine's apt already uses,
# a copy of the source tree without .git (as from a release tarball), and then, inside the root (chroot),
#     bash scripts/quickstart.sh demo
#     bash scripts/quickstart.sh test
# A dependency that the quick start does not install, or a test that needs something only a development
# machine has (git, a warm cache, a pip package, the network), fails here: the test command runs in a network
# namespace with the loopback alone (unshare --net, iproute2's ip). Run by .ci/run as its last stage; needs root.
#
# Usage: bash tests/fresh/fresh_machine.sh [ROOT_DIR]    (default: a new directory under /var/tmp, removed at
#        the end; a given ROOT_DIR is kept, and reused if it already holds a Debian root)
# Environment: FRESH_MIRROR overrides the Debian archive (default: the first one in /etc/apt's sources).
set -euo pipefail
export PATH="$PATH:/usr/sbin:/sbin"  # debootstrap, chroot and ip live there
src=$(cd "$(dirname "$0")/../.." && pwd)
[ "$(id -u)" -eq 0 ] || { echo "fresh_machine.sh: needs root (debootstrap, chroot, mount)" >&2; exit 2; }

keep=1
root=${1:-}
if [ -z "$root" ]; then
  root=$(mktemp -d /var/tmp/chainsim-fresh.XXXXXX)
  keep=0
fi
mkdir -p "$root"
root=$(cd "$root" && pwd)

step() { printf '\n== fresh machine: %s (%s)\n' "$1" "$(date -u +%H:%M:%S)"; }

# The archive apt already reaches (deb822 .sources or one-line .list), unless FRESH_MIRROR says otherwise.
mirror=${FRESH_MIRROR:-}
if [ -z "$mirror" ]; then
  mirror=$( (cat /etc/apt/sources.list.d/*.sources /etc/apt/sources.list 2>/dev/null || true) \
           | sed -nE '/security/d; s/^URIs:[[:space:]]*//p; s/^deb (\[[^]]*\] )?//p' | awk 'NR == 1 {print $1}')
fi
[ -n "$mirror" ] || { echo "fresh_machine.sh: no Debian archive found in /etc/apt; set FRESH_MIRROR" >&2; exit 2; }

mounted=()
cleanup() {
  local i
  for (( i=${#mounted[@]}-1; i>=0; i-- )); do umount -R -l "${mounted[$i]}" 2>/dev/null || true; done
  if [ "$keep" -eq 0 ]; then rm -rf --one-file-system "$root"; fi
}
trap cleanup EXIT

# The tools of this stage on the host: debootstrap, and iproute2's ip for the offline namespace.
tools=()
command -v debootstrap >/dev/null || tools+=(debootstrap)
command -v ip >/dev/null || tools+=(iproute2)
if [ ${#tools[@]} -gt 0 ]; then
  step "installing ${tools[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq -o DPkg::Lock::Timeout=600 "${tools[@]}" >/dev/null
fi
if [ ! -x "$root/usr/bin/apt-get" ]; then
  step "debootstrap --variant=minbase bookworm from $mirror"
  debootstrap --variant=minbase bookworm "$root" "$mirror" >"$root.debootstrap.log" 2>&1 \
    || { tail -n 30 "$root.debootstrap.log" >&2; exit 1; }
  rm -f "$root.debootstrap.log"
fi

# apt inside the root reads the same archives as this machine (updates and security included).
if ls /etc/apt/sources.list.d/*.sources >/dev/null 2>&1; then
  for f in /etc/apt/sources.list.d/*.sources; do
    grep -q 'debian' "$f" && cp "$f" "$root/etc/apt/sources.list.d/"
  done
  ls "$root"/etc/apt/sources.list.d/*.sources >/dev/null 2>&1 && rm -f "$root/etc/apt/sources.list"
fi
cp /etc/resolv.conf "$root/etc/resolv.conf"
# debootstrap writes no /etc/hosts; an installed Debian has one, and local clusters resolve localhost by it.
[ -e "$root/etc/hosts" ] || printf '127.0.0.1\tlocalhost\n::1\t\tlocalhost ip6-localhost ip6-loopback\n' >"$root/etc/hosts"

step "copying the source tree (no .git, no build or results directories)"
rm -rf "$root/src/chainsim"
mkdir -p "$root/src/chainsim"
tar -C "$src" --exclude=./.git --exclude='./build*' --exclude='./results*' --exclude=./out \
    --exclude='__pycache__' -cf - . | tar -C "$root/src/chainsim" -xf -

for d in proc sys dev; do
  mount --rbind "/$d" "$root/$d"
  mount --make-rslave "$root/$d"
  mounted+=("$root/$d")
done

in_root() {
  chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM=dumb \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin bash -c "cd /src/chainsim && $1"
}
# The same without a network: a network namespace of its own with only the loopback up (Dask's local
# clusters use it). Once the quick start has installed the packages, nothing may reach outside.
in_root_offline() {
  unshare --net -- bash -c 'ip link set lo up && exec "$@"' _ \
    chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM=dumb \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin bash -c "cd /src/chainsim && $1"
}
step "in the fresh root: git is absent"
in_root '! command -v git'
step "in the fresh root: bash scripts/quickstart.sh demo"
in_root 'bash scripts/quickstart.sh demo'
in_root 'test -s results/summary.csv && test -s results/figures/falling_chain.png'
step "in the fresh root, without a network: bash scripts/quickstart.sh test"
in_root_offline '! getent hosts deb.debian.org >/dev/null'
in_root_offline 'bash scripts/quickstart.sh test'
step "done"
