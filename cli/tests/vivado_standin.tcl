# A stand-in for Vivado's Tcl commands, for running snapgen's generated Vivado scripts where
# Vivado is not installed (cli/tests/zynq.rs). It is not a model of Vivado: every command that
# tclsh does not know is recorded (one line per call on stdout: "CALL", the words, separated by
# the unit separator \x1f) and answers with a placeholder object, except the few queries whose
# answers steer the scripts, which answer what the environment says:
#
#   STANDIN_BOARD_PARTS   get_board_parts of one part (default: the part asked for)
#   STANDIN_LATEST_PARTS  get_board_parts -latest_file_version (default: the pattern asked for)
#   STANDIN_FCLK_MHZ      get_property CONFIG.PCW_ACT_FPGA0_PERIPHERAL_FREQMHZ (default 100.000000)
#   STANDIN_SETUP_SLACK   get_property SLACK of a path get_timing_paths -setup gave (default 0.250)
#   STANDIN_HOLD_SLACK    ... of one get_timing_paths -hold gave (default 0.050)
#   STANDIN_PROGRESS      get_property PROGRESS (default 100%)
#
# and two that act as Vivado's runs would on the disk: `launch_runs impl_1 ... -to_step
# write_bitstream` leaves TOP.bit (TOP: the last `set_property top`) in impl_1's directory,
# ./standin_runs/impl_1, which `get_property DIRECTORY` of a run answers.
#
# Usage: tclsh vivado_standin.tcl SCRIPT
# Runs SCRIPT as Vivado would source it; the exit status is 1, with the error on stderr, when
# the script raises an error.

proc standin_env {name default} {
    if {[info exists ::env($name)]} { return $::env($name) }
    return $default
}

set ::standin_top ""
set ::standin_run [file join [pwd] standin_runs impl_1]

proc unknown {cmd args} {
    puts [join [concat [list CALL $cmd] $args] "\x1f"]
    switch -- $cmd {
        set_property {
            if {[lindex $args 0] eq "top"} { set ::standin_top [lindex $args 1] }
        }
        launch_runs {
            if {[lindex $args 0] eq "impl_1" && [lsearch $args -to_step] >= 0
                && [lindex $args [expr {[lsearch $args -to_step] + 1}]] eq "write_bitstream"} {
                file mkdir $::standin_run
                close [open [file join $::standin_run $::standin_top.bit] w]
            }
        }
        get_board_parts {
            set asked [lindex $args end]
            if {[lsearch $args -latest_file_version] >= 0} {
                return [standin_env STANDIN_LATEST_PARTS $asked]
            }
            return [standin_env STANDIN_BOARD_PARTS $asked]
        }
        get_timing_paths {
            # A path object that says which check it is.
            if {[lsearch $args -hold] >= 0} { return "<path:hold>" }
            return "<path:setup>"
        }
        get_property {
            switch -- [lindex $args 0] {
                CONFIG.PCW_ACT_FPGA0_PERIPHERAL_FREQMHZ { return [standin_env STANDIN_FCLK_MHZ 100.000000] }
                SLACK {
                    if {[lindex $args 1] eq "<path:hold>"} {
                        return [standin_env STANDIN_HOLD_SLACK 0.050]
                    }
                    return [standin_env STANDIN_SETUP_SLACK 0.250]
                }
                PROGRESS { return [standin_env STANDIN_PROGRESS 100%] }
                DIRECTORY { return $::standin_run }
            }
            return "<property [lindex $args 0]>"
        }
        make_wrapper { return "/standin/wrapper.v" }
        get_bd_pins - get_bd_ports - get_bd_intf_pins - get_bd_cells - get_ports {
            # An object that names what was asked for, so that a connection shows its ends.
            return "<$cmd:[join [concat {*}$args] ,]>"
        }
    }
    return "<$cmd>"
}

if {[catch {source [lindex $argv 0]} message]} {
    puts stderr $message
    exit 1
}
exit 0
