#!/usr/bin/env bash
# The README's two commands in a stock Debian 12 root, as a newcomer runs them.
#
#   sudo bash scripts/stock_debian.sh ROOT [COMMIT]
#
# ROOT: a folder for the Debian root, made with `debootstrap --variant=minbase bookworm`
# when it holds none (debootstrap from Debian's packages; a few minutes). Only python3,
# git and sudo are added to it. The repository's COMMIT (default HEAD) is cloned into
# ROOT/home/newcomer/synth, then `bash scripts/demo.sh` and `bash .ci/run` run there as
# root inside the chroot, each timed; their output goes to ROOT/home/newcomer/*.log.
# Exit 0 when both behave as the README says (demo.sh 0, .ci/run 0).
set -euo pipefail
root="${1:?usage: stock_debian.sh ROOT [COMMIT]}"
commit="${2:-HEAD}"
repo="$(cd "$(dirname "$0")/.." && pwd)"
mirror="${SYNTH_DEBIAN_MIRROR:-http://deb.debian.org/debian}"

if [ ! -x "$root/usr/bin/apt-get" ]; then
  command -v debootstrap >/dev/null || { apt-get update -qq && apt-get install -y -qq debootstrap >/dev/null; }
  debootstrap --variant=minbase bookworm "$root" "$mirror"
fi
cleanup() { for m in dev/pts dev proc sys; do umount -l "$root/$m" 2>/dev/null || true; done; }
trap cleanup EXIT
mount -t proc proc "$root/proc"
mount -t sysfs sys "$root/sys"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
cp /etc/resolv.conf "$root/etc/resolv.conf"
# The host's way out, nothing more: where the network is reached through a TLS proxy, the
# host's CA bundle (pip and git inside the root trust what the host trusts).
ca=()
if [ -f /etc/ssl/certs/ca-certificates.crt ]; then
  mkdir -p "$root/etc/ssl/certs"
  cp /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/certs/host-ca.crt"
  ca=(PIP_CERT=/etc/ssl/certs/host-ca.crt SSL_CERT_FILE=/etc/ssl/certs/host-ca.crt REQUESTS_CA_BUNDLE=/etc/ssl/certs/host-ca.crt)
fi
in_root() { chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 CI=true "${ca[@]}" "$@"; }
in_root bash -c 'apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3 git sudo >/dev/null'

home="$root/home/newcomer"
rm -rf "$home/synth"
mkdir -p "$home"
git clone -q "$repo" "$home/synth"
git -C "$home/synth" checkout -q "$commit"

status=0
for job in "scripts/demo.sh" ".ci/run"; do
  log="$home/$(basename "$job").log"
  start=$(date +%s)
  if in_root bash -c "cd /home/newcomer/synth && bash $job" >"$log" 2>&1; then code=0; else code=$?; fi
  echo "== bash $job: exit $code in $(( $(date +%s) - start )) s (log: $log)"
  tail -n 3 "$log"
  [ "$code" = 0 ] || status=1
done
exit "$status"
