! Fortran interface of the tethash detector: module `tethash`, bind(C) interfaces to include/tethash/tethash.h.
! Compile this file with your code (a .mod file is specific to a compiler) and link tethash::core.
!
! Layout: real(c_double) :: x(3, n) and integer(c_int32_t) :: tets(4, m) are the C API's row-major n x 3 and
! m x 4 arrays. Indices are 0-based (subtract 1 from Fortran's 1-based vertex numbers). Every function returns
! a status, TETHASH_OK = 0; tethash_error_message() gives the message of the last failure on this thread.
module tethash
  use, intrinsic :: iso_c_binding
  implicit none
  private :: c_strlen, tethash_int32_setter

  integer(c_int), parameter :: TETHASH_OK = 0
  integer(c_int), parameter :: TETHASH_ERROR_NULL_ARGUMENT = 1
  integer(c_int), parameter :: TETHASH_ERROR_INVALID_ARGUMENT = 2
  integer(c_int), parameter :: TETHASH_ERROR_STATE = 3
  integer(c_int), parameter :: TETHASH_ERROR_OUT_OF_MEMORY = 4
  integer(c_int), parameter :: TETHASH_ERROR_INTERNAL = 5
  integer(c_int32_t), parameter :: TETHASH_CELL_SIZE_AUTO = 0, TETHASH_CELL_SIZE_ABSOLUTE = 1, &
                               TETHASH_CELL_SIZE_FACTOR = 2
  integer(c_int32_t), parameter :: TETHASH_HASH_COLUMN = 0, TETHASH_HASH_TESCHNER = 1

  type, bind(C) :: tethash_contact
    integer(c_int32_t) :: vertex, tet, vertex_object, tet_object
    real(c_double) :: bary(4)
    real(c_double) :: depth
    real(c_double) :: direction(3)
  end type tethash_contact

  type, bind(C) :: tethash_stats
    real(c_double) :: ms_total, cell_size
    integer(c_int64_t) :: table_size, contacts
    integer(c_int32_t) :: reused, threads
  end type tethash_stats

  ! The setters of one int32_t parameter: tethash_detector_set_threads(detector, threads) and
  ! tethash_detector_set_hash(detector, hash) (TETHASH_HASH_*), the value passed as `value`.
  abstract interface
    function tethash_int32_setter(detector, value) bind(C) result(status)
      import :: c_ptr, c_int, c_int32_t
      type(c_ptr), value :: detector
      integer(c_int32_t), value :: value
      integer(c_int) :: status
    end function
  end interface
  procedure(tethash_int32_setter), bind(C, name="tethash_detector_set_threads") :: tethash_detector_set_threads
  procedure(tethash_int32_setter), bind(C, name="tethash_detector_set_hash") :: tethash_detector_set_hash

  interface
    function tethash_detector_create(detector) bind(C, name="tethash_detector_create") result(status)
      import :: c_ptr, c_int
      type(c_ptr), intent(out) :: detector
      integer(c_int) :: status
    end function
    subroutine tethash_detector_destroy(detector) bind(C, name="tethash_detector_destroy")
      import :: c_ptr
      type(c_ptr), value :: detector
    end subroutine
    function tethash_detector_set_cell_size(detector, mode, value) bind(C, name="tethash_detector_set_cell_size") &
        result(status)
      import :: c_ptr, c_int, c_int32_t, c_double
      type(c_ptr), value :: detector
      integer(c_int32_t), value :: mode
      real(c_double), value :: value
      integer(c_int) :: status
    end function
    function tethash_detector_set_table_size(detector, buckets) bind(C, name="tethash_detector_set_table_size") &
        result(status)
      import :: c_ptr, c_int, c_int64_t
      type(c_ptr), value :: detector
      integer(c_int64_t), value :: buckets
      integer(c_int) :: status
    end function
    function tethash_detector_set_skin(detector, skin) bind(C, name="tethash_detector_set_skin") result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: detector
      real(c_double), value :: skin
      integer(c_int) :: status
    end function
    function tethash_detector_set_object_options(detector, object, self_collision, is_static) &
        bind(C, name="tethash_detector_set_object_options") result(status)
      import :: c_ptr, c_int, c_int32_t
      type(c_ptr), value :: detector
      integer(c_int32_t), value :: object, self_collision, is_static
      integer(c_int) :: status
    end function
    ! vertex_object / tet_object: c_loc of an integer(c_int32_t) array, or c_null_ptr (all objects 0).
    function tethash_detector_set_topology(detector, tets, num_tets, num_vertices, vertex_object, tet_object) &
        bind(C, name="tethash_detector_set_topology") result(status)
      import :: c_ptr, c_int, c_int32_t, c_int64_t
      type(c_ptr), value :: detector
      integer(c_int32_t), intent(in) :: tets(*)
      integer(c_int64_t), value :: num_tets, num_vertices
      type(c_ptr), value :: vertex_object, tet_object
      integer(c_int) :: status
    end function
    function tethash_detector_detect(detector, positions, num_vertices, count) bind(C, name="tethash_detector_detect") &
        result(status)
      import :: c_ptr, c_int, c_int64_t, c_double
      type(c_ptr), value :: detector
      real(c_double), intent(in) :: positions(*)
      integer(c_int64_t), value :: num_vertices
      integer(c_int64_t), intent(out) :: count
      integer(c_int) :: status
    end function
    function tethash_detector_contact_count(detector, count) bind(C, name="tethash_detector_contact_count") &
        result(status)
      import :: c_ptr, c_int, c_int64_t
      type(c_ptr), value :: detector
      integer(c_int64_t), intent(out) :: count
      integer(c_int) :: status
    end function
    ! i is 0-based.
    function tethash_detector_contact(detector, i, contact) bind(C, name="tethash_detector_contact") result(status)
      import :: c_ptr, c_int, c_int64_t, tethash_contact
      type(c_ptr), value :: detector
      integer(c_int64_t), value :: i
      type(tethash_contact), intent(out) :: contact
      integer(c_int) :: status
    end function
    ! Absent optional arrays are not filled: vertex(capacity), tet(capacity), bary(4, capacity), depth(capacity),
    ! direction(3, capacity).
    function tethash_detector_get_contacts(detector, capacity, vertex, tet, bary, depth, direction) &
        bind(C, name="tethash_detector_get_contacts") result(status)
      import :: c_ptr, c_int, c_int32_t, c_int64_t, c_double
      type(c_ptr), value :: detector
      integer(c_int64_t), value :: capacity
      integer(c_int32_t), intent(out), optional :: vertex(*), tet(*)
      real(c_double), intent(out), optional :: bary(*), depth(*), direction(*)
      integer(c_int) :: status
    end function
    ! Edge-face contacts (tethash.h): boundary edges crossing boundary triangles at positions(3, num_vertices).
    function tethash_detector_find_edge_contacts(detector, positions, num_vertices, count) &
        bind(C, name="tethash_detector_find_edge_contacts") result(status)
      import :: c_ptr, c_int, c_int64_t, c_double
      type(c_ptr), value :: detector
      real(c_double), intent(in) :: positions(*)
      integer(c_int64_t), value :: num_vertices
      integer(c_int64_t), intent(out) :: count
      integer(c_int) :: status
    end function
    ! Absent optional arrays are not filled: edge(2, capacity) and face(3, capacity) (0-based vertex ids),
    ! objects(2, capacity), t(capacity), face_bary(3, capacity), inner_end(capacity), normal(3, capacity).
    function tethash_detector_get_edge_contacts(detector, capacity, edge, face, objects, t, face_bary, inner_end, &
                                                normal) bind(C, name="tethash_detector_get_edge_contacts") result(status)
      import :: c_ptr, c_int, c_int32_t, c_int64_t, c_double
      type(c_ptr), value :: detector
      integer(c_int64_t), value :: capacity
      integer(c_int32_t), intent(out), optional :: edge(*), face(*), objects(*), inner_end(*)
      real(c_double), intent(out), optional :: t(*), face_bary(*), normal(*)
      integer(c_int) :: status
    end function
    function tethash_detector_detect_continuous(detector, start, end, num_vertices, tolerance, max_iterations, &
                                                count) bind(C, name="tethash_detector_detect_continuous") result(status)
      import :: c_ptr, c_int, c_int64_t, c_double
      type(c_ptr), value :: detector
      real(c_double), intent(in) :: start(*), end(*)
      integer(c_int64_t), value :: num_vertices
      real(c_double), value :: tolerance
      integer(c_int64_t), value :: max_iterations
      integer(c_int64_t), intent(out) :: count
      integer(c_int) :: status
    end function
    ! Absent optional arrays are not filled: kind(capacity) (0 vertex-face, 1 edge-edge), vertices(4, capacity)
    ! (0-based vertex ids: the vertex and the face's corners, or the two edges' ends), toi(capacity).
    function tethash_detector_get_continuous_contacts(detector, capacity, kind, vertices, toi) &
        bind(C, name="tethash_detector_get_continuous_contacts") result(status)
      import :: c_ptr, c_int, c_int32_t, c_int64_t, c_double
      type(c_ptr), value :: detector
      integer(c_int64_t), value :: capacity
      integer(c_int32_t), intent(out), optional :: kind(*), vertices(*)
      real(c_double), intent(out), optional :: toi(*)
      integer(c_int) :: status
    end function
    ! rest(3, num_vertices), vertex_group(num_vertices) (0-based groups), reach_sq(num_groups): squared reaches.
    function tethash_detector_set_continuous_locality(detector, rest, num_vertices, vertex_group, reach_sq, &
                                                      num_groups) &
        bind(C, name="tethash_detector_set_continuous_locality") result(status)
      import :: c_ptr, c_int, c_int32_t, c_int64_t, c_double
      type(c_ptr), value :: detector
      real(c_double), intent(in) :: rest(*)
      integer(c_int64_t), value :: num_vertices
      integer(c_int32_t), intent(in) :: vertex_group(*)
      real(c_double), intent(in) :: reach_sq(*)
      integer(c_int64_t), value :: num_groups
      integer(c_int) :: status
    end function
    function tethash_detector_continuous_broad_phase_pairs(detector, pairs) &
        bind(C, name="tethash_detector_continuous_broad_phase_pairs") result(status)
      import :: c_ptr, c_int, c_int64_t
      type(c_ptr), value :: detector
      integer(c_int64_t), intent(out) :: pairs
      integer(c_int) :: status
    end function
    function tethash_detector_compute_penetration(detector, positions, num_vertices) &
        bind(C, name="tethash_detector_compute_penetration") result(status)
      import :: c_ptr, c_int, c_int64_t, c_double
      type(c_ptr), value :: detector
      real(c_double), intent(in) :: positions(*)
      integer(c_int64_t), value :: num_vertices
      integer(c_int) :: status
    end function
    function tethash_detector_stats(detector, stats) bind(C, name="tethash_detector_stats") result(status)
      import :: c_ptr, c_int, tethash_stats
      type(c_ptr), value :: detector
      type(tethash_stats), intent(out) :: stats
      integer(c_int) :: status
    end function
    ! Continuous queries: start and end are real(c_double) :: x(3, 4) (vertex, triangle corners; or the two edges).
    function tethash_ccd_vertex_face(start, end, tolerance, max_iterations, hit, toi) &
        bind(C, name="tethash_ccd_vertex_face") result(status)
      import :: c_double, c_int64_t, c_int32_t, c_int
      real(c_double), intent(in) :: start(3, 4), end(3, 4)
      real(c_double), value :: tolerance
      integer(c_int64_t), value :: max_iterations
      integer(c_int32_t), intent(out) :: hit
      real(c_double), intent(out) :: toi
      integer(c_int) :: status
    end function
    function tethash_ccd_edge_edge(start, end, tolerance, max_iterations, hit, toi) &
        bind(C, name="tethash_ccd_edge_edge") result(status)
      import :: c_double, c_int64_t, c_int32_t, c_int
      real(c_double), intent(in) :: start(3, 4), end(3, 4)
      real(c_double), value :: tolerance
      integer(c_int64_t), value :: max_iterations
      integer(c_int32_t), intent(out) :: hit
      real(c_double), intent(out) :: toi
      integer(c_int) :: status
    end function
    function tethash_last_error() bind(C, name="tethash_last_error") result(message)
      import :: c_ptr
      type(c_ptr) :: message
    end function
    function c_strlen(s) bind(C, name="strlen") result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: s
      integer(c_size_t) :: n
    end function
  end interface

contains

  ! The message of the last failing call on this thread, as a Fortran string.
  function tethash_error_message() result(message)
    character(len=:), allocatable :: message
    type(c_ptr) :: p
    character(kind=c_char), pointer :: chars(:)
    integer :: n, k
    p = tethash_last_error()
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate (character(len=n) :: message)
    do k = 1, n
      message(k:k) = chars(k)
    end do
  end function tethash_error_message

end module tethash
