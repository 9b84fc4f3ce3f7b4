#!/usr/bin/env bash
# Installs the procamd component into a scratch DESTDIR and checks that every
# file is in place, that an out-of-tree plugin builds against the installed
# header through pkg-config, and that the installed procamd loads it.
#   check_install.sh BUILD_DIR PLUGIN_SOURCE
set -euo pipefail
build=$1 plugin_src=$2
dest=$(mktemp -d)
trap 'rm -rf "$dest"' EXIT
DESTDIR=$dest cmake --install "$build" --component procamd >/dev/null
prefix=$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$build/CMakeCache.txt")
root=$dest$prefix
for f in sbin/procamd bin/procamctl include/procamd/procam_plugin.h \
         share/doc/procamd/examples/procamd.toml lib/systemd/system/procamd.service \
         lib/systemd/system/procamd.socket lib/udev/rules.d/70-procamd.rules; do
  if [[ ! -e $root/$f && ! -e $dest/$f ]]; then
    echo "missing after install: $f"; find "$dest" -type f; exit 1
  fi
done
# Every file follows the install prefix (--prefix at install time), the units and
# the udev rule included: nothing lands outside it.
moved=$(mktemp -d)
trap 'rm -rf "$dest" "$moved"' EXIT
cmake --install "$build" --component procamd --prefix "$moved/p" >"$moved/log" ||
  { cat "$moved/log"; exit 1; }
outside=$(grep -E '^-- (Installing|Up-to-date): ' "$moved/log" | sed -E 's/^-- [A-Za-z-]+: //' |
          grep -v "^$moved/p/" || true)
[[ -z $outside ]] || { echo "installed outside --prefix $moved/p:"; echo "$outside"; exit 1; }
for f in lib/systemd/system/procamd.service lib/udev/rules.d/70-procamd.rules sbin/procamd \
         share/man/man8/procamd.8.gz share/bash-completion/completions/procamctl; do
  [[ -e $moved/p/$f ]] || { echo "missing under --prefix: $f"; find "$moved" -type f; exit 1; }
done

pc=$(find "$dest" -name procamd-plugin.pc | head -1)
[[ -n $pc ]] || { echo "procamd-plugin.pc not installed"; exit 1; }
export PKG_CONFIG_PATH=$(dirname "$pc") PKG_CONFIG_SYSROOT_DIR=$dest
cflags=$(pkg-config --cflags procamd-plugin)
plugin_dir=$(pkg-config --variable=pluginsdir procamd-plugin)  # sysroot included
[[ -d $plugin_dir ]] || { echo "plugin directory $plugin_dir not installed"; exit 1; }
mkdir "$dest/out-of-tree"
${CC:-cc} -shared -fPIC -fvisibility=hidden $cflags "$plugin_src" -o "$dest/out-of-tree/libconstant_tilt.so"
listing=$("$root/sbin/procamd" --list-drivers --plugin-dir "$dest/out-of-tree")
echo "$listing"
grep -q "^tilt  *constant-tilt  *$dest/out-of-tree/libconstant_tilt.so" <<<"$listing" ||
  { echo "installed procamd did not load the out-of-tree plugin"; exit 1; }
echo "install: complete; out-of-tree plugin built with pkg-config and loaded"
