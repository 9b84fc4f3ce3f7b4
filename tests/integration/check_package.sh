#!/usr/bin/env bash
# Builds the Debian package (./procam package) and checks it as an installer meets
# it: every path in place, the installed units verified by systemd-analyze, the
# installed daemon checking the packaged configuration, the maintainer scripts run
# against stand-ins of the system commands, every option of every tool's --help in
# its manual page, the completion scripts parsed, and lintian when it is installed.
#   check_package.sh SOURCE_DIR
set -euo pipefail
src=$(readlink -f "$1")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for tool in dpkg-deb cpack; do
  command -v $tool >/dev/null || { echo "$tool not installed"; exit 77; }
done
fail() { echo "package: $*" >&2; exit 1; }

(cd "$src" && ./procam --no-deps package) >"$work/package.log" 2>&1 ||
  { tail -40 "$work/package.log"; fail "./procam package failed"; }
deb=$src/$(tail -1 "$work/package.log")
[[ -f $deb ]] || fail "no package built"
echo "built $(basename "$deb") ($(stat -c %s "$deb") bytes)"
root=$work/root
dpkg-deb -x "$deb" "$root"
dpkg-deb -e "$deb" "$work/control"

# Paths: Debian's (prefix /usr, configuration in /etc, merged /usr for units and rules).
tools=(procamctl procam-calibrate procam-keystone procam-sim procam-render)
paths=(usr/sbin/procamd etc/procamd/procamd.toml usr/share/doc/procamd/examples/procamd.toml
       usr/lib/systemd/system/procamd.service usr/lib/systemd/system/procamd.socket
       usr/lib/udev/rules.d/70-procamd.rules usr/include/procamd/procam_plugin.h
       usr/share/doc/procamd/PROTOCOL.md usr/share/doc/procamd/copyright
       usr/share/doc/procamd/changelog.gz usr/share/man/man8/procamd.8.gz
       usr/share/man/man5/procamd.toml.5.gz)
for t in "${tools[@]}"; do
  [[ $t == procamctl ]] || paths+=("usr/share/man/man1/$t.1.gz")
  paths+=("usr/bin/$t" "usr/share/bash-completion/completions/$t")
done
paths+=(usr/share/man/man1/procamctl.1.gz usr/share/bash-completion/completions/procamd)
for p in "${paths[@]}"; do [[ -e $root/$p ]] || fail "missing /$p"; done
pc=$(find "$root/usr/lib" -name procamd-plugin.pc | head -1)
[[ -n $pc ]] || fail "missing procamd-plugin.pc"
[[ -d $(dirname "$(dirname "$pc")")/procamd/plugins ]] || fail "missing the plugin directory"
grep -qx '/etc/procamd/procamd.toml' "$work/control/conffiles" || fail "procamd.toml is no conffile"
grep -q '^Depends:.*adduser' "$work/control/control" || fail "no dependency on adduser"
nothing_else=$(cd "$root" && find . -type f | grep -vE '^\./(usr|etc/procamd)/' || true)
[[ -z $nothing_else ]] || fail "files outside /usr and /etc/procamd: $nothing_else"
service=$root/usr/lib/systemd/system/procamd.service
grep -qx 'ExecStart=/usr/sbin/procamd --config /etc/procamd/procamd.toml' "$service" ||
  fail "ExecStart does not run /usr/sbin/procamd on /etc/procamd/procamd.toml"
grep -qx 'ExecStartPre=/usr/sbin/procamd --check-config /etc/procamd/procamd.toml' "$service" ||
  fail "no ExecStartPre configuration check"
echo "paths: ${#paths[@]} checked, conffile and units point at /usr/sbin and /etc"

# The installed daemon accepts the configuration it ships with.
"$root/usr/sbin/procamd" --version
"$root/usr/sbin/procamd" --check-config "$root/etc/procamd/procamd.toml" \
  --plugin-dir "$work" || fail "the packaged configuration does not pass --check-config"

# The installed units and rules (and their man: documentation).
MANPATH=$root/usr/share/man "$src/tests/integration/check_units.sh" "$service" \
  "$root/usr/lib/systemd/system/procamd.socket" "$root/usr/lib/udev/rules.d/70-procamd.rules" \
  "$root/usr/sbin/procamd"

# --help and the manual page agree: every option --help names is in the page.
check_page() {  # PAGE.gz HELP-TEXT
  local page=$1 help=$2 text missing=()
  text=$(zcat "$page")
  while read -r opt; do
    grep -qF -- "$opt" <<<"$text" || missing+=("$opt")
  done < <(grep -oE '(^|[^A-Za-z0-9_-])--?[A-Za-z][A-Za-z0-9-]*' <<<"$help" |
           sed -E 's/^[^-]*//' | sort -u)
  [[ ${#missing[@]} -eq 0 ]] || fail "$(basename "$page") lacks ${missing[*]}"
  if command -v man >/dev/null; then
    MANWIDTH=80 man -l "$page" >/dev/null 2>"$work/man.err" || fail "man -l $page failed"
    [[ ! -s $work/man.err ]] || fail "man -l $page: $(cat "$work/man.err")"
  fi
}
check_page "$root/usr/share/man/man8/procamd.8.gz" "$("$root/usr/sbin/procamd" --help)"
for t in "${tools[@]}"; do
  check_page "$root/usr/share/man/man1/$t.1.gz" "$("$root/usr/bin/$t" --help 2>&1 || true)"
done
echo "manual pages: every --help option documented"
for f in "$root"/usr/share/bash-completion/completions/*; do bash -n "$f" || fail "$f"; done

# Maintainer scripts, against stand-ins that log their arguments.
for s in postinst prerm postrm; do sh -n "$work/control/$s" || fail "$s does not parse"; done
standins=$work/standins
mkdir -p "$standins"
for cmd in addgroup adduser udevadm systemctl deb-systemd-helper deb-systemd-invoke; do
  printf '#!/bin/sh\necho "%s $*" >>"%s"\nexit 0\n' "$cmd" "$work/calls" >"$standins/$cmd"
done
# getent: nothing exists yet, unless PROCAM_TEST_USERS says so.
printf '#!/bin/sh\n[ -n "$PROCAM_TEST_USERS" ]\n' >"$standins/getent"
# deb-systemd-helper was-enabled: as PROCAM_TEST_ENABLED says.
printf '#!/bin/sh\necho "deb-systemd-helper $*" >>"%s"\n[ "$2" = was-enabled ] && [ -z "$PROCAM_TEST_ENABLED" ] && exit 1\nexit 0\n' \
  "$work/calls" >"$standins/deb-systemd-helper"
chmod +x "$standins"/*
run() {  # SCRIPT ARGS...: the script's calls, one per line
  : >"$work/calls"
  env PATH="$standins:$PATH" "$work/control/$1" "${@:2}" || fail "$1 $* exited $?"
  cat "$work/calls"
}
calls=$(run postinst configure)
grep -q '^addgroup --system --quiet procam$' <<<"$calls" || fail "postinst made no procam group: $calls"
grep -q '^adduser --system .*--ingroup procam .*procam$' <<<"$calls" || fail "postinst made no procam user: $calls"
grep -q '^deb-systemd-helper enable procamd.service$' <<<"$calls" || fail "postinst did not enable: $calls"
! grep -qE 'start|restart' <<<"$calls" || fail "postinst started the service: $calls"
if [[ -d /run/udev ]]; then
  grep -q '^udevadm control --reload-rules$' <<<"$calls" || fail "postinst did not reload udev: $calls"
fi
calls=$(PROCAM_TEST_USERS=1 run postinst configure 0.0.9)  # an upgrade, service disabled
! grep -qE '^add(user|group)' <<<"$calls" || fail "postinst made the user twice: $calls"
! grep -q '^deb-systemd-helper enable' <<<"$calls" || fail "an upgrade enabled a disabled service: $calls"
calls=$(PROCAM_TEST_USERS=1 PROCAM_TEST_ENABLED=1 run postinst configure 0.0.9)
grep -q '^deb-systemd-helper enable procamd.service$' <<<"$calls" || fail "an upgrade disabled it: $calls"
state=$work/dpkgroot/var/lib/procamd
mkdir -p "$state" && echo '{}' >"$state/rig.json"
DPKG_ROOT=$work/dpkgroot run postrm remove >/dev/null
[[ -f $state/rig.json ]] || fail "removal deleted the state directory"
calls=$(DPKG_ROOT=$work/dpkgroot run postrm purge)
[[ ! -e $state ]] || fail "purge left the state directory"
grep -q '^deb-systemd-helper purge procamd.service$' <<<"$calls" || fail "purge: $calls"
echo "maintainer scripts: user and group made once, enabled not started, state kept until purge"

if command -v lintian >/dev/null; then
  lintian --fail-on error,warning "$deb" 2>&1 | grep -v 'root privileges' || true
  lintian --fail-on error,warning "$deb" >/dev/null 2>&1 || fail "lintian reports errors or warnings"
  echo "lintian: no errors, no warnings"
else
  echo "lintian: not installed, skipped"
fi
echo "package: complete"
