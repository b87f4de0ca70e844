#!/bin/sh
# Builds the lamprig .deb from a staged install with Debian's own tools (`make deb` runs it
# after `make install DESTDIR=STAGE/root PREFIX=/usr`):
#   dpkg-shlibdeps  the Depends of the libraries the binaries link
#   dpkg-gencontrol DEBIAN/control from tools/debian/control + changelog, Installed-Size
#   dpkg-deb        the package (root:root owned, without fakeroot)
# usage: build-deb.sh STAGE OUTDIR
# A cross package (make deb-arm64) runs it under `dpkg-architecture -aARCH -c` with STRIP set
# to the cross strip and LR_SHLIBDEPS_ARGS to extra dpkg-shlibdeps options (-Sdir for the
# libraries unpacked rather than installed; tools/cross/arm64.mk).
set -eu
stage=$1
out=$2
here=$(cd "$(dirname "$0")" && pwd)
root=$stage/root
src=$stage/src

# One version: the VERSION file (what `lamprig --version` prints) and the changelog's top entry
# must agree, or the package would claim a version the binary does not.
version=$(cat "$here/../../VERSION")
changelog_version=$(dpkg-parsechangelog -l "$here/changelog" -S Version)
if [ "$version" != "$changelog_version" ]; then
    echo "build-deb.sh: VERSION says $version, tools/debian/changelog says $changelog_version" >&2
    exit 1
fi

# What dh_strip, dh_installman, dh_installchangelogs and dh_installdocs would do.
for b in "$root"/usr/bin/*; do
    ${STRIP:-strip} --strip-unneeded --remove-section=.comment --remove-section=.note "$b"
done
gzip -9n "$root"/usr/share/man/man1/*.1
install -d "$root/usr/share/doc/lamprig"
install -m 0644 "$here/copyright" "$root/usr/share/doc/lamprig/copyright"
gzip -9nc "$here/changelog" > "$root/usr/share/doc/lamprig/changelog.gz"
chmod 0644 "$root/usr/share/doc/lamprig/changelog.gz"

install -d "$root/DEBIAN"
for s in postinst postrm prerm; do
    install -m 0755 "$here/$s" "$root/DEBIAN/$s"
done
install -m 0644 "$here/conffiles" "$root/DEBIAN/conffiles"

# dpkg-shlibdeps and dpkg-gencontrol read ./debian/: a scratch source directory.
install -d "$src/debian"
cp "$here/control" "$here/changelog" "$src/debian/"
abs_root=$(cd "$root" && pwd)
(
    cd "$src"
    # shellcheck disable=SC2086
    dpkg-shlibdeps ${LR_SHLIBDEPS_ARGS:-} -Tdebian/substvars "$abs_root"/usr/bin/*
    dpkg-gencontrol -plamprig -Vmisc:Depends= -Tdebian/substvars -fdebian/files -P"$abs_root"
)

(cd "$root" && find . -path ./DEBIAN -prune -o -type f -printf '%P\0' | sort -z |
    xargs -0 md5sum) > "$root/DEBIAN/md5sums"
chmod 0644 "$root/DEBIAN/md5sums" "$root/DEBIAN/control"
# Directories 0755, files as installed: a umask of the builder must not leak in.
find "$root" -type d -exec chmod 0755 {} +
dpkg-deb --root-owner-group -Zxz --build "$root" "$out"
