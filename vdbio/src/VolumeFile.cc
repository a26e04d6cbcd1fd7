// placeholder: filled in by the pipeline work (issue 4)
