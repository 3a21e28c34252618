"""The figures: one module per figure, the panels they share, what they draw (picks)
and how (style). They read tables; plot functions take ``ax`` and compute nothing.
Imports nothing, so that each figure's rule depends on its own code only."""
