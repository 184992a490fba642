# Sourced by the fault tests: a cgroup that holds its processes to a share of
# one core. `ip netns exec` mounts a fresh /sys, so the cpu controller is
# mounted here (cgroup v1 "cpu", else v2 with cpu.max); a machine with
# neither fails the test that asked.
#
#   quota_mount                 once: mounts the controller ($quota_root)
#   quota_group NAME PERCENT    makes $quota_root/NAME at PERCENT of a core
#   quota_put NAME PID          moves PID (all its threads) into it
#   quota_release PID           moves PID back to the root group
#   quota_unmount               removes the groups and the mount
quota_root=""
quota_v=""
quota_mount() {
  quota_root=$(mktemp -d /tmp/fahr-quota-XXXXXX)
  if mount -t cgroup -o cpu cgroup "$quota_root" 2>/dev/null; then
    quota_v=1
  elif mount -t cgroup2 none "$quota_root" 2>/dev/null && grep -qw cpu "$quota_root/cgroup.controllers"; then
    quota_v=2
    echo +cpu >"$quota_root/cgroup.subtree_control" 2>/dev/null || true
  else
    rmdir "$quota_root"; quota_root=""
    echo "cpu_quota: cannot mount a cgroup cpu controller (v1 cpu or v2 cpu.max)" >&2
    return 1
  fi
}
quota_group() {
  local dir="$quota_root/$1" quota_us=$(( $2 * 1000 ))
  mkdir -p "$dir"
  if [ "$quota_v" = 1 ]; then
    echo 100000 >"$dir/cpu.cfs_period_us"
    echo "$quota_us" >"$dir/cpu.cfs_quota_us"
  else
    echo "$quota_us 100000" >"$dir/cpu.max"
  fi
}
quota_put() { echo "$2" >"$quota_root/$1/cgroup.procs"; }
quota_release() { echo "$1" >"$quota_root/cgroup.procs" 2>/dev/null || true; }
quota_unmount() {
  [ -n "$quota_root" ] || return 0
  for dir in "$quota_root"/*/; do
    [ -e "$dir/cgroup.procs" ] || continue
    while read -r pid; do quota_release "$pid"; done <"$dir/cgroup.procs"
    rmdir "$dir" 2>/dev/null || true
  done
  umount "$quota_root" 2>/dev/null || true
  rmdir "$quota_root" 2>/dev/null || true
}
