"""OpenCL C sources of the pipeline stages (installed as the package cltess.kernels)."""
