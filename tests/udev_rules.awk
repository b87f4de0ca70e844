# A parser of udev rules files (udev(7) syntax): each rule line is comma-separated
# KEY[{attribute}] OPERATOR "value" pairs; comments and blank lines are skipped. Fails (exit 1,
# one message per fault naming line and text) on an unknown key, an operator the key does not
# take, an unquoted value, an unbalanced quote, a GOTO without its LABEL. Prints a summary.
function fault(msg) { printf "%s:%d: %s: %s\n", FILENAME, FNR, msg, $0; bad++ }
BEGIN {
    nmatch = split("ACTION DEVPATH KERNEL KERNELS NAME SYMLINK SUBSYSTEM SUBSYSTEMS DRIVER " \
                   "DRIVERS TAG TAGS TEST PROGRAM RESULT CONST", m, " ")
    for (i = 1; i <= nmatch; i++) matchkey[m[i]] = 1
    nassign = split("NAME SYMLINK OWNER GROUP MODE TAG RUN LABEL GOTO IMPORT OPTIONS SECLABEL " \
                    "OWNER", a, " ")
    for (i = 1; i <= nassign; i++) assignkey[a[i]] = 1
    split("ATTR ATTRS ENV SYSCTL", w, " ")
    for (i in w) attrkey[w[i]] = 1
}
/^[ \t]*(#|$)/ { next }
{
    line = $0
    sub(/[ \t]+$/, "", line)
    if (line ~ /\\$/) { fault("line continuation not supported here"); next }
    rest = line
    while (length(rest) > 0) {
        sub(/^[ \t]*/, "", rest)
        if (!match(rest, /^[A-Z_]+(\{[^}]+\})?[ \t]*(==|!=|\+=|-=|:=|=)[ \t]*"/)) {
            fault("expected KEY OP \"value\" at '" rest "'"); break
        }
        pair = substr(rest, 1, RLENGTH)
        rest = substr(rest, RLENGTH + 1)
        q = index(rest, "\"")
        if (!q) { fault("unterminated value"); break }
        value = substr(rest, 1, q - 1)
        rest = substr(rest, q + 1)
        key = pair; sub(/[{ \t=!+:-].*/, "", key)
        op = pair; sub(/^[^=!+:-]*[ \t]*/, "", op); sub(/[ \t]*"$/, "", op)
        if (pair ~ /\{/ && !(key in attrkey) && key != "IMPORT" && key != "RUN" && key != "TEST")
            fault("key " key " takes no {attribute}")
        else if (pair !~ /\{/ && (key in attrkey))
            fault("key " key " needs an {attribute}")
        else if (!(key in matchkey) && !(key in assignkey) && !(key in attrkey))
            fault("unknown key " key)
        else if ((op == "==" || op == "!=") && !(key in matchkey) && !(key in attrkey))
            fault("key " key " cannot be matched")
        else if (op != "==" && op != "!=" && !(key in assignkey) && key != "ENV" && key != "ATTR" \
                 && key != "SYSCTL")
            fault("key " key " cannot be assigned")
        if (key == "GOTO") gotos[value] = FNR
        if (key == "LABEL") labels[value] = 1
        if (key == "MODE" && value !~ /^0?[0-7][0-7][0-7]$/) fault("MODE " value " is not octal")
        if ((key == "ATTR" || key == "ATTRS") && pair ~ /id(Vendor|Product)/ && value !~ /^[0-9a-f][0-9a-f][0-9a-f][0-9a-f]$/)
            fault("USB id " value " is not 4 lowercase hex digits")
        npairs++
        sub(/^[ \t]*/, "", rest)
        if (length(rest) > 0) {
            if (substr(rest, 1, 1) != ",") { fault("expected ',' at '" rest "'"); break }
            rest = substr(rest, 2)
        }
    }
    rules++
}
END {
    for (g in gotos) if (!(g in labels)) { printf "GOTO %s (line %d) has no LABEL\n", g, gotos[g]; bad++ }
    if (bad) exit 1
    printf "%d rules, %d pairs\n", rules, npairs
}
