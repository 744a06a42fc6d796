#!/usr/bin/env bash
# Puts darktable's measured camera noise profiles (noiseprofiles.json, darktable's data under its GPL
# licence; never committed here) where the library looks for them (darktableProfilesPath()):
#   ${RAWGMENT_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/rawgment}/darktable/noiseprofiles.json
# from an installed darktable, or else extracted from Debian's darktable package, downloaded without
# installing it (darktable's GUI and its dependencies stay off the machine). Idempotent.
set -euo pipefail
cache=${RAWGMENT_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/rawgment}
dest="$cache/darktable/noiseprofiles.json"
if [ -s "$dest" ]; then
  echo "fetch-darktable-profiles: $dest present"
  exit 0
fi
mkdir -p "$(dirname "$dest")"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ -s /usr/share/darktable/noiseprofiles.json ]; then
  cp /usr/share/darktable/noiseprofiles.json "$work/noiseprofiles.json"
else
  echo "fetch-darktable-profiles: downloading Debian's darktable package for its noiseprofiles.json"
  if ! (cd "$work" && apt-get download -qq darktable 2>/dev/null); then
    # A fresh machine may have no package lists yet.
    sudo_cmd=()
    [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
    "${sudo_cmd[@]}" apt-get update -qq
    (cd "$work" && apt-get download -qq darktable)
  fi
  # The .deb is read in the temporary folder, whoever owns it (apt may fetch as the _apt user).
  deb=$(ls "$work"/darktable_*.deb)
  dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$work" ./usr/share/darktable/noiseprofiles.json
  mv "$work/usr/share/darktable/noiseprofiles.json" "$work/noiseprofiles.json"
fi
# A truncated download must not stand in for the file: it is parsed before it is put in place.
/usr/bin/python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); assert d["noiseprofiles"]' \
  "$work/noiseprofiles.json"
mv "$work/noiseprofiles.json" "$dest.tmp.$$"
mv "$dest.tmp.$$" "$dest"
echo "fetch-darktable-profiles: wrote $dest"
