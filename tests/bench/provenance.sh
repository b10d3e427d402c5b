# SPDX-License-Identifier: GPL-3.0-or-later
# provenance: one line for a result page, after its command (sourced:
# `. tests/bench/provenance.sh`): when it ran, the build (the checkout's
# commit, and whether it had uncommitted changes outside the results and
# the documents) and the machine (cores, CPU model, load average before).
provenance() {
	local when build cpu
	when=$(date -u '+%Y-%m-%d %H:%M UTC')
	build=$(git rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
	if ! git diff --quiet HEAD -- . ':!tests/bench/results' ':!docs' ':!README.md' 2>/dev/null; then
		build="$build with uncommitted changes"
	fi
	cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -1)
	echo "Run $when, build $build, $(nproc) cores (${cpu:-$(uname -m)}), load average $(cut -d' ' -f1-3 /proc/loadavg) before."
}

# stamp FILE LINE: LINE (a provenance) into a result page written by a
# program that does not print one, after its title and the blank line
# that follows it (at the top if it has no title).
stamp() {
	local f=$1 line=$2
	awk -v p="$line" 'NR == 1 && !/^#/ { print p; print ""; done = 1 }
		{ print }
		!done && NR > 1 && /^$/ { print p; print ""; done = 1 }' "$f" > "$f.stamp" && mv "$f.stamp" "$f"
}
