"""The mutation check behind scripts/mutate (docs/reliability.md, "Mutation check"): mutants
(the list read and checked), runner (a mutant applied, built, tested and restored) and cli
(the command and its report)."""
