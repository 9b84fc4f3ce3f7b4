#!/usr/bin/env bash
# Checks procamd's systemd units with systemd-analyze verify and its udev rules
# with udevadm test. Both tools report problems on stderr/stdout but exit 0, so
# any diagnostic counts as a failure.
#   check_units.sh SERVICE SOCKET RULES PROCAMD_BINARY   (MANPATH: where the pages are)
set -euo pipefail
service=$1 socket=$2 rules=$3 procamd=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

if ! command -v systemd-analyze >/dev/null; then
  echo "systemd-analyze not installed"; exit 77
fi
# verify needs binaries that exist here: point ExecStart(Pre) at the given one.
sed -E "s|^(ExecStart(Pre)?=)[^ ]*|\1$procamd|" "$service" >"$work/procamd.service"
cp "$socket" "$work/procamd.socket"
# Documentation=man:… is checked where the pages are (MANPATH given, man installed).
man_check=--man=no
[[ -n ${MANPATH:-} ]] && command -v man >/dev/null && man_check=--man=yes
(cd "$work" && systemd-analyze verify "$man_check" ./procamd.service ./procamd.socket) \
  >"$work/verify.out" 2>&1 ||
  echo "(systemd-analyze exited with status $?)" >>"$work/verify.out"
if [[ -s $work/verify.out ]]; then
  echo "systemd-analyze verify reported:"; cat "$work/verify.out"; exit 1
fi
echo "systemd-analyze verify: clean"

# udevadm test needs root and a private mount namespace for the rules directory.
if [[ $(id -u) -ne 0 ]] || ! command -v unshare >/dev/null || ! command -v udevadm >/dev/null; then
  echo "udev rules: skipped (needs root, unshare and udevadm)"; exit 0
fi
mkdir "$work/rules"
cp "$rules" "$work/rules/"
name=$(basename "$rules")
unshare -m sh -c "mount --bind '$work/rules' /etc/udev/rules.d && udevadm test --action=add /sys/class/net/lo" \
  >"$work/udev.out" 2>&1 || true
# Only what udevadm says about the copy under test counts: a procamd rule already
# installed on this machine (e.g. /usr/local/lib/udev/rules.d) is overridden by it
# and reported as skipped, which is not a problem of the rules. The procam group
# only exists where procamd is installed.
problems=$(grep -F "/etc/udev/rules.d/$name" "$work/udev.out" | grep -v "Reading rules file" |
           grep -v "Unknown group 'procam'" || true)
if ! grep -q "Reading rules file: /etc/udev/rules.d/$name" "$work/udev.out"; then
  echo "udevadm test did not read $name:"; cat "$work/udev.out"; exit 1
fi
if [[ -n $problems ]]; then
  echo "udevadm test reported:"; echo "$problems"; exit 1
fi
echo "udev rules: clean"
