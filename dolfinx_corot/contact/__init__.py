"""Node-to-segment contact: search, kernels, interfaces."""
