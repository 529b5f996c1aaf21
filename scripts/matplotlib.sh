# Sourced by the scripts that draw plots (figures.sh, accuracy.sh, performance.sh): Debian's
# python3-matplotlib, installed when missing, before any measuring, so that a long run does not end in
# an ImportError.
dpkg-query -W -f='${Status}' python3-matplotlib 2>/dev/null | grep -q "install ok installed" || {
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends python3-matplotlib >/dev/null
}
