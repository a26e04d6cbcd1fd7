// placeholder: filled in by the gas work (issue 5)
