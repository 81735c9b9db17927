# The 3-D Cosserat order-2 rows of tests/cli/vci_rates.sh (its header says what and why), split off so that the
# two halves of that study run side by side under tests/run.sh; not under SAN=1.
VCI_RATES_PART=cosserat3d source "$(dirname "$0")/vci_rates.sh"
