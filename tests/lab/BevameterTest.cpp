// Virtual bevameter on a tiny bed (docs/lab.md); cases follow with the lab scenario.
