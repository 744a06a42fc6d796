#!/usr/bin/env bash
# The Debian package, built and proven (an opt-in stage, like build-in-opencv.sh):
#  1. configures build/deb for /usr (-DRAWGMENT_DEBIAN_PACKAGE=ON), builds the library, apps and Python
#     module, and makes build/deb/rawgment_<version>_<arch>.deb with CPack;
#  2. runs lintian on it: any error fails;
#  3. installs it in a throwaway root laid over this machine's own (an overlay mount in a private mount
#     namespace: nothing of this machine changes), and there (packaging/debian/prove-installed.sh) runs
#     every app's --help from PATH, imports rawgment with no PYTHONPATH, builds test/downstream with CMake
#     (no CMAKE_PREFIX_PATH) and with pkg-config, and purges the package;
#  4. after the purge, lists what the throwaway root holds beyond dpkg's own records: it must be nothing.
# Needs root (or sudo) for the mounts, as the install script does for apt.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=${RAWGMENT_JOBS:-$(nproc)}
bash "$root/scripts/install-deps.sh" --packaging

build="$root/build/deb"
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
echo "=== package-deb.sh: build ($build)"
mkdir -p "$build"
cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
  -DRAWGMENT_DEBIAN_PACKAGE=ON -DRAWGMENT_BUILD_PYTHON=ON -DRAWGMENT_BUILD_TESTS=OFF -DRAWGMENT_BUILD_PERF=OFF \
  -DRAWGMENT_BUILD_SAMPLES=OFF > "$build/configure.log" || { cat "$build/configure.log"; exit 1; }
cmake --build "$build" --parallel "$jobs"
rm -f "$build"/rawgment_*.deb
(cd "$build" && cpack > cpack.log) || { cat "$build/cpack.log"; exit 1; }
debs=("$build"/rawgment_*.deb)
[ "${#debs[@]}" -eq 1 ] && [ -f "${debs[0]}" ] || { echo "package-deb: cpack made no single .deb" >&2; exit 1; }
deb=${debs[0]}
dpkg-deb --info "$deb" | sed -n '/Package:/,$p'

echo "=== package-deb.sh: lintian"
lintian --fail-on error --tag-display-limit 0 "$deb"

echo "=== package-deb.sh: install, use and purge in a throwaway root"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
scratch=$(mktemp -d "${TMPDIR:-/tmp}/rawgment-deb-root.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/payload" "$scratch/fs"
cp "$deb" "$scratch/payload/"
cp -r "$root/test/downstream" "$scratch/payload/downstream"
cp "$root/packaging/debian/prove-installed.sh" "$scratch/payload/"
"${sudo_cmd[@]}" unshare --mount --propagation private bash -euo pipefail -c '
  scratch=$1
  deb=$2
  mount -t tmpfs tmpfs "$scratch/fs"
  mkdir "$scratch/fs/upper" "$scratch/fs/work" "$scratch/fs/root"
  mount -t overlay overlay -o "lowerdir=/,upperdir=$scratch/fs/upper,workdir=$scratch/fs/work" "$scratch/fs/root"
  mount -t proc proc "$scratch/fs/root/proc"
  mount --rbind /dev "$scratch/fs/root/dev"
  mount --rbind /sys "$scratch/fs/root/sys"
  mkdir -p "$scratch/fs/root/tmp/rawgment-proof"
  mount --bind "$scratch/payload" "$scratch/fs/root/tmp/rawgment-proof"
  chroot "$scratch/fs/root" /bin/bash /tmp/rawgment-proof/prove-installed.sh \
    "/tmp/rawgment-proof/$(basename "$deb")" /tmp/rawgment-proof/downstream
  umount "$scratch/fs/root/tmp/rawgment-proof"
  # What the install, the use and the purge changed in the root, less dpkg'"'"'s records and logs, the
  # caches of the loader and of man-db (rebuilt by their triggers) and the scratch folders of the proof.
  cd "$scratch/fs/upper"
  left=$(find . -mindepth 1 \( -type f -o -type l -o -type c \) \
           ! -path "./var/lib/dpkg/*" ! -path "./var/log/*" ! -path "./var/cache/ldconfig/*" ! -path "./var/cache/man/*" \
           ! -path "./etc/ld.so.cache" ! -path "./tmp/*" ! -path "./root/*" | sort)
  if [ -n "$left" ]; then
    echo "package-deb: the purged package left files in the root:" >&2
    echo "$left" >&2
    exit 1
  fi
' _ "$scratch" "$deb"
echo "=== package-deb.sh: $(basename "$deb") built, lintian-clean, installed, used and purged without a trace"
