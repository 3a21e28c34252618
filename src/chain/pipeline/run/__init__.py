"""What happens around Snakemake: the result store and its reuse, the run folder's
checksums, the patches to Snakemake's scheduler, the end of a process."""
