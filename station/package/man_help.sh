#!/bin/sh
# help2man reads a subcommand's --help through this (CMakeLists.txt, "Manual pages"): it runs
# `station SUB --help` and marks the footer's "Exit status:" as help2man's custom section
# "*Exit status*", so the page has an EXIT STATUS section made from what the code returns.
"$@" | sed 's/^Exit status:$/*Exit status*/'
